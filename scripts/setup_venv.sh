#!/usr/bin/env bash
# Creates (or reuses) the Python virtual environment with the independent test peers, and prints
# its interpreter's path on the last line of stdout (everything else goes to stderr).
#
#   TC_PYTHON="$(bash scripts/setup_venv.sh | tail -n 1)"
#
# Location: $TC_VENV, default ~/.cache/thickness_collision/venv. A venv is reused only when it is
# complete: its interpreter runs and its stamp file records exactly the package list below (the
# stamp is written last, after every package installed and imported). Otherwise it is (re)built in
# place; a venv whose interpreter no longer runs is cleared first. Set TC_VENV_FORCE=1 to reinstall.
set -euo pipefail
venv="${TC_VENV:-$HOME/.cache/thickness_collision/venv}"
python="${TC_BASE_PYTHON:-python3}"

# The pinned peers (design.md, "Real peers for tests"). Checked to install as wheels on CPython
# 3.11 / x86_64 Debian; yourdfpy pulls trimesh[easy] (scipy, shapely, lxml, ...).
packages=(
    "numpy>=2,<3"               # coal 3.0.3's eigenpy is built against numpy 2
    "coal==3.0.3"               # hpp-fcl's successor: the checker MoveIt-style planners use
    "python-fcl==0.7.0.*"       # FCL 0.7 bindings
    "rosbags==0.11.9"           # rosbag2 MCAP and sqlite3 reader/writer, no ROS needed
    "cyclonedds==11.0.1"        # an independent ROS 2 DDS peer (bundles its C library)
    "example-robot-data==6.0.0" # robot URDFs + meshes under <site-packages>/cmeel.prefix/share
    "mcap-ros2-support==0.6.0"  # a second, independent MCAP/ROS 2 reader
    "yourdfpy==0.0.60"          # an independent URDF parser and FK
    "xacro==2.1.1"              # ROS's xacro, to expand MoveIt's .xacro configs as users do
    "zstandard==0.25.0"         # zstd bindings: compresses bags as rosbag2 does (tests/replay_compressed.rs)
    "ruckig==0.19.4"            # jerk-limited time parameterisation (benches/trajectory.rs's trajectories)
    "maturin==1.16.0"           # builds the Python package (python/) into this venv (tests/python_package.rs)
    "pytest==9.2.0"             # runs the Python package's tests
    "ompl==2.0.1"               # OMPL's own wheel (nanobind): the package's validators (python/tests/test_ompl.py)
)
stamp="$venv/.tc-packages"
want="$("$python" -c 'import sys; print(sys.version.split()[0])') ${packages[*]}"

if [ "${TC_VENV_FORCE:-0}" != 1 ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ] \
    && "$venv/bin/python" -c '' 2>/dev/null; then
    echo "setup_venv: reusing $venv" >&2
else
    start=$(date +%s)
    rm -f "$stamp"
    clear=()
    if [ -e "$venv" ] && ! "$venv/bin/python" -c '' 2>/dev/null; then
        clear=(--clear) # a broken or half-made venv
    fi
    if ! "$python" -m venv "${clear[@]}" "$venv" >&2; then
        # Debian's python3 without python3-venv has no ensurepip: fall back to virtualenv.
        echo "setup_venv: '$python -m venv' failed, trying virtualenv" >&2
        "$python" -m pip install --quiet --user virtualenv >&2
        "$python" -m virtualenv "${clear[@]}" "$venv" >&2
    fi
    export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_INPUT=1
    "$venv/bin/python" -m pip install --quiet --prefer-binary "${packages[@]}" >&2
    # Complete means importable, not just unpacked (example-robot-data is data only: check it by
    # its metadata and its share folder).
    "$venv/bin/python" - >&2 <<'EOF'
import importlib.metadata as md, os, site
import coal, fcl, numpy, rosbags, cyclonedds, mcap_ros2, yourdfpy, xacro, zstandard, ruckig, maturin, pytest, ompl.base
share = [os.path.join(p, "cmeel.prefix", "share", "example-robot-data") for p in site.getsitepackages()]
assert any(os.path.isdir(s) for s in share), f"example-robot-data share folder missing: {share}"
print("setup_venv: " + ", ".join(f"{p} {md.version(p)}" for p in [
    "numpy", "coal", "python-fcl", "rosbags", "cyclonedds", "example-robot-data",
    "mcap-ros2-support", "yourdfpy", "xacro", "zstandard", "ruckig", "maturin", "pytest", "ompl"]))
EOF
    echo "$want" > "$stamp"
    echo "setup_venv: installed into $venv in $(( $(date +%s) - start )) s" >&2
fi
echo "$venv/bin/python"
