#!/usr/bin/env bash
# Every test: installs what the C tests and rendered examples need when it
# is missing (scripts/setup-c.sh), then runs the whole workspace's tests.
# Extra arguments go to cargo test.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/setup-c.sh
cargo test --workspace "$@"
