#!/usr/bin/env bash
# A portable bundle of lmbake for a many-core machine that has none of its libraries
# (../shared/tools/portable/, docs/threads.md#many-cores): builds lmbake in build-bundle with
# OpenImageIO linked in (the bundle tool follows the binary's linked libraries, and the default
# build loads OIIO as a module it would not see), then makes the bundle.
#   usage: tools/make_bundle.sh [OUT.tar.xz]   (default: lmbundle.tar.xz)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-lmbundle.tar.xz}
portable=../shared/tools/portable
[ -x "$portable/make-bundle.sh" ] || { echo "make_bundle: $portable/make-bundle.sh not found"; exit 1; }
LMB_BUILD_TARGETS=lmbake tools/setup.sh build-bundle -DLMB_IMAGES_MODULE=OFF -DBUILD_TESTING=OFF
"$portable/make-bundle.sh" build-bundle "$out"
