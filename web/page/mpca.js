// mpca in the browser: loads mpca_web.wasm (web/src/wasm.rs) and wraps its
// exports. No dependencies and no generated glue: the module imports
// nothing, and a world is read back as an image in the module's memory.
//
//   import { load, SMOKE, WATER } from './mpca.js';
//   const mpca = await load();
//   const smoke = mpca.scene(SMOKE, 7);   // scene number, seed
//   smoke.step(2);
//   context.putImageData(smoke.image(), 0, 0);

export const SMOKE = 0;
export const WATER = 1;

export async function load(url = new URL('mpca_web.wasm', import.meta.url)) {
    const bytes = await (await fetch(url)).arrayBuffer();
    const { instance } = await WebAssembly.instantiate(bytes, {});
    return new Mpca(instance.exports);
}

class Mpca {
    constructor(exports) {
        this.x = exports;
        this.size = exports.mpca_web_size();
    }

    // Builds scene `kind` (SMOKE or WATER) with `seed`; throws if refused,
    // with the status (mpca_status's number) and the field or part at fault.
    scene(kind, seed) {
        const status = this.x.mpca_web_init(kind, seed >>> 0);
        if (status !== 0) throw new Error(`mpca: scene ${kind} refused, status ${status}: ${this.lastError()}`);
        return new Scene(this, kind);
    }

    // The field or part at fault in the last refused call
    // ("desc.emitter_capacity"), "" while none was: static text in the
    // module's memory, read up to its NUL.
    lastError() {
        const at = this.x.mpca_web_error();
        if (at === 0) return '';
        const bytes = new Uint8Array(this.x.memory.buffer, at);
        return new TextDecoder().decode(bytes.subarray(0, bytes.indexOf(0)));
    }
}

class Scene {
    constructor(mpca, kind) {
        this.m = mpca;
        this.kind = kind;
    }

    step(steps = 1) {
        this.m.x.mpca_web_step(this.kind, steps);
    }

    // The world's hash (M8) as 16 hex digits, as mpca_world_hash prints it.
    hash() {
        return BigInt.asUintN(64, this.m.x.mpca_web_hash(this.kind)).toString(16).padStart(16, '0');
    }

    particles() {
        return this.m.x.mpca_web_particles(this.kind);
    }

    // An emitter at cell (x, y), y up; false when the table is full (why:
    // lastError of the module).
    emit(x, y) {
        return this.m.x.mpca_web_emit(this.kind, x, y) === 0;
    }

    // The world drawn as size x size RGBA pixels, top row first: a view of
    // the module's memory, valid until the next call.
    image() {
        const n = this.m.size;
        const at = this.m.x.mpca_web_render(this.kind);
        return new ImageData(new Uint8ClampedArray(this.m.x.memory.buffer, at, n * n * 4), n, n);
    }
}
