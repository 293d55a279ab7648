#!/usr/bin/env bash
# Installs kerf under a prefix: the binaries in PREFIX/bin (kerf and the node binaries
# trajectory_executor, mjto_planner, milling_planner, gcode_planner), the shipped data in
# PREFIX/share/kerf (the share directory an installed kerf finds beside its binary,
# kerf_robot::data: KERF_DATA_DIR, then <exe dir>/../share/kerf, then the source tree) and the
# ROS 2 launch file as PREFIX/share/kerf/launch/kerf.launch.py, which runs PREFIX/bin/<node>
# on that data:
#
#   ros2 launch PREFIX/share/kerf/launch/kerf.launch.py robot:=laser_cutter
#
#   launch_scripts/install.sh PREFIX                          # build (release) and install all
#   launch_scripts/install.sh PREFIX --binary-only            # only the binaries
#   launch_scripts/install.sh PREFIX --data-only              # only the data and the launch file
#   launch_scripts/install.sh PREFIX --binaries-from DIR      # the binaries already built in DIR
#                                                             # (e.g. target/release), no build
#
# The binaries are built by one `cargo build --release --locked` of the five packages (the
# same binaries as `cargo install --path <package>` of each, sharing one build) and copied
# into PREFIX/bin.
#
# The data keeps the source tree's relative layout:
#   urdf/                                   robot descriptions, limits, meshes, cells, milling cell
#   crates/mjto/cases/                      the laser-cutting cases of seed 001
#   crates/millplan/policies/               the milling planner's shipped policies
#   crates/stepping/weights/                the stepping agent's network (kerf step --controller ddqn)
#   crates/cornernet/weights/               the learned NURBS corner (G-code method drls-net)
#   crates/millplan/data/indicator_cache.bin  the indicator cache of the default cell
#   crates/gcode/data/programs/             the shipped G-code programs (package://kerf/...)
#   launch_scripts/params/                  each robot's launch configuration
#   launch/kerf.launch.py                   the ROS 2 launch file
# An existing PREFIX/share/kerf is replaced.
set -euo pipefail

usage() {
  echo "usage: $0 PREFIX [--binary-only|--data-only] [--binaries-from DIR]" >&2
  exit 2
}

[ $# -ge 1 ] || usage
prefix=$1
shift
case "$prefix" in
  -*) usage ;;
esac
mode=all
binaries_from=
while [ $# -gt 0 ]; do
  case "$1" in
    --binary-only | --data-only)
      [ "$mode" = all ] || usage
      mode=$1
      ;;
    --binaries-from)
      [ $# -ge 2 ] && [ -z "$binaries_from" ] || usage
      binaries_from=$2
      case "$binaries_from" in
        -* | "") usage ;;
      esac
      shift
      ;;
    *) usage ;;
  esac
  shift
done
if [ -n "$binaries_from" ] && [ "$mode" = --data-only ]; then
  echo "$0: --binaries-from installs binaries; --data-only installs none" >&2
  usage
fi

src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# package:binary of everything installed in PREFIX/bin.
binaries=(
  kerf:kerf
  kerf_trajectory_executor:trajectory_executor
  kerf_mjto_planner:mjto_planner
  kerf_milling_planner:milling_planner
  kerf_gcode_planner:gcode_planner
)

if [ "$mode" != --data-only ]; then
  if [ -n "$binaries_from" ]; then
    from=$(cd "$binaries_from" 2>/dev/null && pwd) || {
      echo "$0: --binaries-from $binaries_from: not a directory" >&2
      exit 1
    }
  else
    packages=()
    for pb in "${binaries[@]}"; do
      packages+=(-p "${pb%%:*}")
    done
    (cd "$src" && cargo build --release --locked "${packages[@]}")
    from=${CARGO_TARGET_DIR:-$src/target}/release
    case "$from" in
      /*) ;;
      *) from=$src/$from ;;
    esac
  fi
  for pb in "${binaries[@]}"; do
    if [ ! -x "$from/${pb#*:}" ]; then
      echo "$0: $from/${pb#*:} is missing (build it: cargo build -p ${pb%%:*})" >&2
      exit 1
    fi
  done
fi

mkdir -p "$prefix"
prefix=$(cd "$prefix" && pwd)

if [ "$mode" != --data-only ]; then
  mkdir -p "$prefix/bin"
  for pb in "${binaries[@]}"; do
    bin=${pb#*:}
    # Copy beside, then rename: a running binary is never overwritten in place.
    cp "$from/$bin" "$prefix/bin/.$bin.new"
    chmod 755 "$prefix/bin/.$bin.new"
    mv -f "$prefix/bin/.$bin.new" "$prefix/bin/$bin"
  done
fi

if [ "$mode" != --binary-only ]; then
  share=$prefix/share/kerf
  data=(
    urdf
    crates/mjto/cases
    crates/millplan/policies
    crates/stepping/weights
    crates/cornernet/weights
    crates/millplan/data/indicator_cache.bin
    crates/gcode/data/programs
    launch_scripts/params
  )
  for rel in "${data[@]}" launch_scripts/kerf.launch.py; do
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
  mkdir -p "$tmp/launch"
  cp "$src/launch_scripts/kerf.launch.py" "$tmp/launch/kerf.launch.py"
  chmod -R u+rwX,go+rX "$tmp"
  rm -rf "$share"
  mv "$tmp" "$share"
  trap - EXIT
  echo "kerf data installed in $share"
  echo "kerf launch file installed as $share/launch/kerf.launch.py"
fi
if [ "$mode" != --data-only ]; then
  echo "kerf installed in $prefix/bin: ${binaries[*]#*:}"
fi
