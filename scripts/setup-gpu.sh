#!/usr/bin/env bash
# Makes sure the GPU backend's tests (gpu/) have an adapter on a machine
# without a GPU: Mesa's lavapipe, a Vulkan driver that runs on the CPU
# (Debian's mesa-vulkan-drivers, which brings the Vulkan loader). Installs
# it when no lavapipe driver is registered (scripts/install-missing.sh).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
if ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1 && ldconfig -p | grep -q 'libvulkan\.so\.1'; then
    echo "lavapipe (Vulkan on the CPU): present"
else
    "$here/install-missing.sh" mesa-vulkan-drivers libvulkan1
fi
