#!/usr/bin/env bash
# Every test: installs what the C tests and rendered examples need when it
# is missing (scripts/setup-c.sh), and a Vulkan driver on the CPU for the
# GPU backend's tests (scripts/setup-gpu.sh), then runs the whole
# workspace's tests.
# Extra arguments go to cargo test.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/setup-c.sh
scripts/setup-gpu.sh
cargo test --workspace "$@"
