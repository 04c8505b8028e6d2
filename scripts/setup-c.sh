#!/usr/bin/env bash
# Makes sure the C side can build: a C and a C++ compiler, make, and the
# OSMesa, libpng and giflib headers the rendered scenes (c_examples/) use,
# and Box2D's (the rigid bodies of c_examples/box2d_pool.cpp); installs
# what is missing (scripts/install-missing.sh).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cc=${CC:-cc}
cxx=${CXX:-c++}
missing=()
command -v make >/dev/null 2>&1 || missing+=(make)
command -v "$cxx" >/dev/null 2>&1 || missing+=(g++)
if ! command -v "$cc" >/dev/null 2>&1; then
    missing+=(gcc libc6-dev libosmesa6-dev libpng-dev libgif-dev libbox2d-dev)
else
    header() { printf '#include <%s>\n' "$1" | "$cc" -E -x c - >/dev/null 2>&1; }
    header GL/osmesa.h || missing+=(libosmesa6-dev)
    header png.h || missing+=(libpng-dev)
    header gif_lib.h || missing+=(libgif-dev)
    # Box2D 2.4 is C++ only; its header is found by the C preprocessor as
    # well, which is all this asks.
    header box2d/box2d.h || missing+=(libbox2d-dev)
fi
if [ ${#missing[@]} -gt 0 ]; then
    "$here/install-missing.sh" "${missing[@]}"
else
    echo "make, $cc, $cxx, OSMesa, libpng, giflib and Box2D headers: present"
fi
