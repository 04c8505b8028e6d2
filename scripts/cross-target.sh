#!/usr/bin/env bash
# M8: the same seed and inputs give bit-identical worlds on every target.
# Runs the scene_hashes program natively and on 32-bit Arm
# (armv7-unknown-linux-gnueabihf) under QEMU user mode, and compares.
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
