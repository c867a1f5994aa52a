#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fetches the Unity C test framework (2.4.3) into third_party/unity without committing it.
# Unity has no package of its own in the registries reachable here; Debian's cjson *source*
# package carries it under tests/unity. We download that source package through a private apt
# configuration (a deb-src entry in a temporary folder; the system's apt setup is not touched)
# and unpack only tests/unity. Users with their own Unity pass -DUNITY_ROOT=... to CMake instead.
set -euo pipefail
dest=${1:-"$(cd "$(dirname "$0")/../.." && pwd)/third_party/unity"}
[ -f "$dest/src/unity.c" ] && exit 0

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/lists/partial" "$tmp/dl"
suite=$(. /etc/os-release 2>/dev/null; echo "${VERSION_CODENAME:-bookworm}")
echo "deb-src http://deb.debian.org/debian $suite main" > "$tmp/sources.list"
O="-o Dir::Etc::SourceList=$tmp/sources.list -o Dir::Etc::SourceParts=/dev/null -o Dir::State::Lists=$tmp/lists -o Debug::NoLocking=1"
echo "fetch_unity: downloading Debian's cjson source package (carries Unity 2.4.3)"
apt-get $O update -q >/dev/null
(cd "$tmp/dl" && apt-get $O source --download-only cjson >/dev/null 2>&1)
orig=$(ls "$tmp"/dl/cjson_*.orig.tar.* | head -n1)
# cJSON's copy of unity_internals.h includes ../examples/unity_config.h: take that file too
tar -xf "$orig" -C "$tmp" --wildcards '*/tests/unity/src/*' '*/tests/unity/examples/unity_config.h'
src=$(ls -d "$tmp"/cJSON-*/tests/unity)
mkdir -p "$dest/examples"
cp -r "$src/src" "$dest/"
cp "$src/examples/unity_config.h" "$dest/examples/"
echo "fetch_unity: Unity sources in $dest/src"
