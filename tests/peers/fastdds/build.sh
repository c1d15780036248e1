#!/usr/bin/env bash
# Builds a Fast DDS program (C++, Debian's libfastrtps-dev 2.9 and fastddsgen) against the ROS 2
# types of the Python peers, into target/fastdds/, and prints the binary's path.
#
#   bash tests/peers/fastdds/build.sh NAME SOURCE.cpp [MORE.cpp ...]
#
# The IDL comes from the peers' own field lists (ros_idl.py, with $TC_PYTHON). Everything is cached
# by a hash of its inputs: a rerun with nothing changed builds nothing. Concurrent callers (test
# binaries run in parallel) wait on one lock.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: build.sh NAME SOURCE.cpp [MORE.cpp ...]" >&2; exit 2; }
name=$1
shift
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
out="${CARGO_TARGET_DIR:-$root/target}/fastdds"
python="${TC_PYTHON:-}"
[ -n "$python" ] || { echo "build.sh: TC_PYTHON is not set (bash scripts/setup_venv.sh prints it)" >&2; exit 1; }
for tool in fastddsgen g++; do
    command -v "$tool" >/dev/null || { echo "build.sh: $tool not found (apt-get install fastddsgen libfastrtps-dev g++)" >&2; exit 1; }
done
[ -e /usr/include/fastdds/dds/domain/DomainParticipant.hpp ] || { echo "build.sh: Fast DDS headers not found (apt-get install libfastrtps-dev)" >&2; exit 1; }
mkdir -p "$out"
exec 9>"$out/.lock"
flock 9

CXXFLAGS=(-std=c++17 -O2 -pthread)
tools="$(g++ --version | head -n 1) $(dpkg-query -W -f='${Version}' libfastrtps-dev 2>/dev/null) $(dpkg-query -W -f='${Version}' fastddsgen 2>/dev/null) ${CXXFLAGS[*]}"

# The generated types: one object pair per distinct IDL.
types_hash=$( { echo "$tools"; cat "$here/ros_idl.py" "$root/tests/peers/dds_types.py" "$root/tests/peers/moveit_types.py" \
    "$root"/interfaces/thickness_collision_msgs/msg/*.msg "$root"/interfaces/thickness_collision_msgs/srv/*.srv; } | sha256sum | cut -c1-16)
gen="$out/types-$types_hash"
if [ ! -e "$gen/done" ]; then
    rm -rf "$gen"
    mkdir -p "$gen"
    "$python" "$here/ros_idl.py" "$gen/ros.idl"
    (cd "$gen" && fastddsgen -typeros2 -replace -d . ros.idl >fastddsgen.log 2>&1) || { cat "$gen/fastddsgen.log" >&2; exit 1; }
    g++ "${CXXFLAGS[@]}" -c "$gen/ros.cxx" -o "$gen/ros.o" -I "$gen" &
    g++ "${CXXFLAGS[@]}" -c "$gen/rosPubSubTypes.cxx" -o "$gen/rosPubSubTypes.o" -I "$gen"
    wait $!
    touch "$gen/done"
fi

# The program: its sources, the types and the tools.
shopt -s nullglob
headers=("$here"/*.hpp)
bin_hash=$( { echo "$types_hash $tools"; cat "$@" "${headers[@]}"; } | sha256sum | cut -c1-16)
bin="$out/$name-$bin_hash"
if [ ! -x "$bin" ]; then
    g++ "${CXXFLAGS[@]}" -I "$gen" -I "$here" "$@" "$gen/ros.o" "$gen/rosPubSubTypes.o" -lfastrtps -lfastcdr -o "$bin.tmp"
    mv "$bin.tmp" "$bin"
fi
echo "$bin"
