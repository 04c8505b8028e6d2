#!/usr/bin/env bash
# M8: the same seed and inputs give bit-identical worlds on every target.
# Runs the scene_hashes program natively, on 32-bit Arm
# (armv7-unknown-linux-gnueabihf) and on 64-bit Arm
# (aarch64-unknown-linux-gnu) under QEMU user mode, and compares; on
# 64-bit Arm also the unit test of the Neon code of M5.6 (core/src/rules/assign/hungarian.rs,
# sign_mask). Then the same comparison for a C program linked with
# libmpca.a and libmpca.so on 32-bit Arm.
# Installs the cross linkers and QEMU with apt-get when they are missing.
set -euo pipefail
cd "$(dirname "$0")/.."

need=()
command -v arm-linux-gnueabihf-gcc >/dev/null || need+=(gcc-arm-linux-gnueabihf libc6-dev-armhf-cross)
command -v aarch64-linux-gnu-gcc >/dev/null || need+=(gcc-aarch64-linux-gnu libc6-dev-arm64-cross)
command -v qemu-arm >/dev/null && command -v qemu-aarch64 >/dev/null || need+=(qemu-user)
scripts/install-missing.sh ${need[@]+"${need[@]}"}
for t in armv7-unknown-linux-gnueabihf aarch64-unknown-linux-gnu; do
    rustup target list --installed | grep -qx "$t" || rustup target add "$t"
done
export CARGO_TARGET_ARMV7_UNKNOWN_LINUX_GNUEABIHF_LINKER=arm-linux-gnueabihf-gcc
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="qemu-aarch64 -L /usr/aarch64-linux-gnu"

cargo build --release -p mpca-tests --bin scene_hashes
native=$(target/release/scene_hashes)
echo "x86-64:"; echo "$native"

# The scenes on TARGET, run by QEMU, against x86-64's.
compare() {
    local target=$1 name=$2
    shift 2
    cargo build --release -p mpca-tests --bin scene_hashes --target "$target"
    local other
    other=$("$@" "target/$target/release/scene_hashes")
    echo "$name:"; echo "$other"
    if [ "$native" != "$other" ]; then
        echo "cross-target: the worlds differ between x86-64 and $name" >&2
        exit 1
    fi
    echo "cross-target: $(echo "$native" | wc -l) scenes bit-identical on x86-64 and $name"
}
compare armv7-unknown-linux-gnueabihf "armv7 (qemu-arm)" qemu-arm -L /usr/arm-linux-gnueabihf
compare aarch64-unknown-linux-gnu "aarch64 (qemu-aarch64)" qemu-aarch64 -L /usr/aarch64-linux-gnu
cargo test --release -p mpca --lib --target aarch64-unknown-linux-gnu sign_mask

# The C library on 32-bit Arm: without Rust's std it brings its own
# personality routine for the unwind tables of Rust's prebuilt core
# (ffi/src/sys.rs), which a C program's link there needs. The install
# consumer, linked statically and dynamically, prints the line it prints
# on x86-64.
cargo build --release -p mpca-ffi
cargo build --release -p mpca-ffi --target armv7-unknown-linux-gnueabihf
armlib=$PWD/target/armv7-unknown-linux-gnueabihf/release
ln -sf libmpca.so "$armlib/libmpca.so.0"
bin=$(mktemp -d)
trap 'rm -rf "$bin"' EXIT
cc -std=c99 -Iinclude tests/install/consumer.c target/release/libmpca.a -o "$bin/native"
arm-linux-gnueabihf-gcc -std=c99 -Iinclude tests/install/consumer.c "$armlib/libmpca.a" -o "$bin/arm-static"
arm-linux-gnueabihf-gcc -std=c99 -Iinclude tests/install/consumer.c -L"$armlib" -lmpca -Wl,-rpath,"$armlib" -o "$bin/arm-shared"
native=$("$bin/native")
for link in static shared; do
    arm=$(qemu-arm -L /usr/arm-linux-gnueabihf "$bin/arm-$link")
    echo "libmpca ($link) on armv7: $arm"
    [ "$arm" = "$native" ] || { echo "cross-target: the C program on armv7 ($link) printed '$arm', on x86-64 '$native'" >&2; exit 1; }
done
