#!/usr/bin/env bash
# Installs kerf under a prefix: the binary as PREFIX/bin/kerf and the shipped data as
# PREFIX/share/kerf, the share directory an installed kerf finds beside its binary
# (kerf_robot::data: KERF_DATA_DIR, then <exe dir>/../share/kerf, then the source tree).
#
#   launch_scripts/install.sh PREFIX                 # cargo install --path . --root PREFIX, and the data
#   launch_scripts/install.sh PREFIX --binary-only   # only the binary
#   launch_scripts/install.sh PREFIX --data-only     # only the data (e.g. beside a copied release binary)
#
# The data keeps the source tree's relative layout:
#   urdf/                                   robot descriptions, limits, meshes, the milling cell file
#   crates/mjto/cases/                      the laser-cutting cases of seed 001
#   crates/millplan/policies/               the milling planner's shipped policies
#   crates/millplan/data/indicator_cache.bin  the indicator cache of the default cell
#   crates/gcode/data/programs/             the shipped G-code programs (package://kerf/...)
#   launch_scripts/params/                  the example parameter files
# An existing PREFIX/share/kerf is replaced.
set -euo pipefail

usage() {
  echo "usage: $0 PREFIX [--binary-only|--data-only]" >&2
  exit 2
}

[ $# -ge 1 ] && [ $# -le 2 ] || usage
prefix=$1
mode=${2:-all}
case "$mode" in
  all | --binary-only | --data-only) ;;
  *) usage ;;
esac
case "$prefix" in
  -*) usage ;;
esac

src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mkdir -p "$prefix"
prefix=$(cd "$prefix" && pwd)

if [ "$mode" != --data-only ]; then
  cargo install --locked --path "$src" --root "$prefix"
fi

if [ "$mode" != --binary-only ]; then
  share=$prefix/share/kerf
  data=(
    urdf
    crates/mjto/cases
    crates/millplan/policies
    crates/millplan/data/indicator_cache.bin
    crates/gcode/data/programs
    launch_scripts/params
  )
  for rel in "${data[@]}"; do
    if [ ! -e "$src/$rel" ]; then
      echo "$0: $src/$rel is missing; run this script from a complete kerf source tree" >&2
      exit 1
    fi
  done
  # Build the new share directory beside the old one, then swap, so a failed copy leaves
  # the old one in place.
  mkdir -p "$prefix/share"
  tmp=$(mktemp -d "$prefix/share/.kerf.XXXXXX")
  trap 'rm -rf "$tmp"' EXIT
  for rel in "${data[@]}"; do
    mkdir -p "$tmp/$(dirname "$rel")"
    cp -R "$src/$rel" "$tmp/$rel"
  done
  chmod -R u+rwX,go+rX "$tmp"
  rm -rf "$share"
  mv "$tmp" "$share"
  trap - EXIT
  echo "kerf data installed in $share"
fi
if [ "$mode" != --data-only ]; then
  echo "kerf installed as $prefix/bin/kerf"
fi
