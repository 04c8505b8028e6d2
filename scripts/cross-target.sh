#!/usr/bin/env bash
# M8: the same seed and inputs give bit-identical worlds on every target.
# Runs the scene_hashes program natively and on 32-bit Arm
# (armv7-unknown-linux-gnueabihf) under QEMU user mode, and compares; then
# the same for a C program linked with libmpca.a and libmpca.so.
# Installs the cross linker and QEMU with apt-get when they are missing.
set -euo pipefail
cd "$(dirname "$0")/.."

need=()
command -v arm-linux-gnueabihf-gcc >/dev/null || need+=(gcc-arm-linux-gnueabihf libc6-dev-armhf-cross)
command -v qemu-arm >/dev/null || need+=(qemu-user)
scripts/install-missing.sh ${need[@]+"${need[@]}"}
rustup target list --installed | grep -qx armv7-unknown-linux-gnueabihf || rustup target add armv7-unknown-linux-gnueabihf

cargo build --release -p mpca-tests --bin scene_hashes
CARGO_TARGET_ARMV7_UNKNOWN_LINUX_GNUEABIHF_LINKER=arm-linux-gnueabihf-gcc \
    cargo build --release -p mpca-tests --bin scene_hashes --target armv7-unknown-linux-gnueabihf

native=$(target/release/scene_hashes)
arm=$(qemu-arm -L /usr/arm-linux-gnueabihf target/armv7-unknown-linux-gnueabihf/release/scene_hashes)
echo "x86-64:"; echo "$native"
echo "armv7 (qemu-arm):"; echo "$arm"
if [ "$native" != "$arm" ]; then
    echo "cross-target: the worlds differ between x86-64 and 32-bit Arm" >&2
    exit 1
fi
echo "cross-target: $(echo "$native" | wc -l) scenes bit-identical on x86-64 and armv7"

# The C library on 32-bit Arm: without Rust's std it brings its own
# personality routine for the unwind tables of Rust's prebuilt core
# (ffi/src/sys.rs), which a C program's link there needs. The install
# consumer, linked statically and dynamically, prints the line it prints
# on x86-64.
cargo build --release -p mpca-ffi
CARGO_TARGET_ARMV7_UNKNOWN_LINUX_GNUEABIHF_LINKER=arm-linux-gnueabihf-gcc \
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
