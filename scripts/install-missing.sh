#!/usr/bin/env bash
# Installs the Debian packages named as arguments: with apt-get as root, or
# through sudo; otherwise prints the exact command to run and fails.
#   scripts/install-missing.sh PACKAGE...
set -euo pipefail
[ $# -gt 0 ] || exit 0
if ! command -v apt-get >/dev/null 2>&1; then
    echo "missing: $* (Debian package names); install them, or their equivalents" >&2
    exit 1
fi
if [ "$(id -u)" -eq 0 ]; then
    sudo=()
elif command -v sudo >/dev/null 2>&1; then
    sudo=(sudo)
else
    echo "missing: $*; as root, run:" >&2
    echo "  apt-get update && apt-get install -y $*" >&2
    exit 1
fi
echo "installing: $*"
"${sudo[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "$@"
