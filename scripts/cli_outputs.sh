#!/usr/bin/env bash
# The CLI's answers on the tests' inputs, one file per stream, for comparing two binaries:
#
#   bash scripts/cli_outputs.sh BIN OUTDIR
#   diff -r OUTDIR_A OUTDIR_B
#
# Runs a fixed list of invocations of BIN (`check`, `areas`, `replay`, `run` refusing at start,
# usage errors), drawn from tests/cli_check.rs, cli_areas.rs, replay_bags.rs,
# replay_compressed.rs, hostile_input.rs, input_panics.rs and real_inputs.rs. For invocation N
# (001, 002, ...) it writes OUTDIR/N.cmd (a comment naming the case, then the command with the
# binary as `thickness_collision`), N.out, N.err (standard output and error, masked as below),
# N.rc (the exit code) and, when the command wrote files, N.files/ (a copy of them). An MCAP file
# among them is compared as text: N.files/.../X.mcap.txt (scripts/mcap_text.py: every record and
# every message decoded), masked as below; the file itself moves to OUTDIR.raw/N/.../X.mcap.
#
# Every binary must see the same paths, so the inputs live in one fixed folder,
# $TC_CLI_INPUTS (default /tmp/tc_cli_inputs), written once by scripts/cli_inputs.py (the bags
# with the peers' rosbags; $TC_PYTHON is the peers' venv python) and reused afterwards: delete
# the folder to write it again. Each command runs in that folder with relative paths, a fixed
# environment (`env -i`: the bundled workcell from $TC_CLI_INPUTS/config through
# THICKNESS_COLLISION_CONFIG, no ROS package path, TMPDIR and HOME inside the folder, DDS on
# loopback), standard input from /dev/null and a 60 s timeout (exit 124 then).
#
# Masks: the only figures that vary from run to run are timings. They are replaced, in N.out
# and N.err only, by this sed (nothing else is changed):
#   built in 1.234 ms              -> built in <ms> ms           (areas' report)
#   ...) in 12.3 ms  (end of line)  -> ...) in <ms> ms            (check's "loaded ..." line)
#   time: 0.123 s, 4.56 us per state (219 states/s) -> time: <masked>   (replay's summary)
# and in the MCAP text, by a second sed:
#   check_seconds=1.234e-05        -> check_seconds=<s>          (CollisionReport's check time)
set -u
if [[ $# -ne 2 ]]; then
    echo "usage: $0 BIN OUTDIR" >&2
    exit 2
fi
BIN=$(realpath "$1")
OUT=$2
ROOT=$(cd "$(dirname "$0")/.." && pwd)
IN=${TC_CLI_INPUTS:-/tmp/tc_cli_inputs}
MCAP_MASK='s/check_seconds=[-+0-9.eE]+/check_seconds=<s>/g'
MASK='s/built in [0-9.]+ ms/built in <ms> ms/g; s/\) in [0-9.]+ ms$/) in <ms> ms/; s/^time: [0-9.]+ s, [0-9.]+ us per state \([0-9]+ states\/s\)$/time: <masked>/'

: "${TC_PYTHON:?set TC_PYTHON (the python of the test peers venv: rosbags, mcap-ros2-support)}"
if [[ ! -e $IN/.complete ]]; then
    rm -rf "$IN"
    mkdir -p "$IN"
    "$TC_PYTHON" "$ROOT/scripts/cli_inputs.py" "$IN" "$ROOT" || exit 1
    touch "$IN/.complete"
fi
[[ -e $OUT || -e $OUT.raw ]] && { echo "$OUT or $OUT.raw exists: give a new folder" >&2; exit 2; }
mkdir -p "$OUT"

BASE_ENV=(PATH=/usr/local/bin:/usr/bin:/bin LANG=C.UTF-8 HOME="$IN/home" TMPDIR="$IN/tmp"
    AMENT_PREFIX_PATH=/nonexistent_prefix ROS_LOCALHOST_ONLY=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_DOMAIN_ID=77)
CONFIG_ENV=(THICKNESS_COLLISION_CONFIG="$IN/config")
n=0

# case LABEL [VAR=VALUE ...] -- ARGS...: one invocation. Before it, these may be set for it alone:
# EXE (the program, default the binary), NOCONFIG=1 (no THICKNESS_COLLISION_CONFIG), CLOSED=1
# (standard output is a pipe whose reader is already closed), STDIN (a file for standard input).
case_() {
    local label=$1 envs=() id
    shift
    while [[ $1 != -- ]]; do envs+=("$1"); shift; done
    shift
    n=$((n + 1))
    id=$(printf %03d "$n")
    local exe=${EXE:-$BIN} shown=thickness_collision
    [[ -n ${EXE:-} ]] && shown=$EXE
    local cfg=("${CONFIG_ENV[@]}")
    [[ -n ${NOCONFIG:-} ]] && cfg=()
    {
        echo "# $label"
        [[ -n ${CLOSED:-} ]] && echo "# standard output: a pipe whose reader is closed"
        [[ -n ${STDIN:-} ]] && echo "# standard input: $STDIN"
        printf '%q ' cd "$IN"; printf '&& '
        printf '%q ' env "${envs[@]}" "$shown" "$@"
        echo
    } > "$OUT/$id.cmd"
    rm -rf "$IN/work" "$IN/tmp" "$IN/home"
    mkdir -p "$IN/work" "$IN/tmp" "$IN/home"
    local cmd=(env -i "${BASE_ENV[@]}" "${cfg[@]}" "${envs[@]}" timeout -k 2 60 "$exe" "$@")
    if [[ -n ${CLOSED:-} ]]; then
        cmd=(python3 -c 'import os, subprocess, sys
r, w = os.pipe()
os.close(r)
code = subprocess.run(sys.argv[1:], stdout=w).returncode
sys.exit(code if code >= 0 else 128 - code)' "${cmd[@]}")
    fi
    (cd "$IN" && "${cmd[@]}" < "${STDIN:-/dev/null}" > "$OUT/$id.out" 2> "$OUT/$id.err")
    echo $? > "$OUT/$id.rc"
    sed -E -i "$MASK" "$OUT/$id.out" "$OUT/$id.err"
    if [[ -n $(ls -A "$IN/work") ]]; then
        cp -a "$IN/work" "$OUT/$id.files"
        local f rel
        while IFS= read -r -d '' f; do
            rel=${f#"$OUT/$id.files/"}
            "$TC_PYTHON" "$ROOT/scripts/mcap_text.py" "$f" > "$f.txt"
            sed -E -i "$MCAP_MASK" "$f.txt"
            mkdir -p "$(dirname "$OUT.raw/$id/$rel")"
            mv "$f" "$OUT.raw/$id/$rel"
        done < <(find "$OUT/$id.files" -name '*.mcap' -print0)
    fi
    EXE='' NOCONFIG='' CLOSED='' STDIN=''
}
c() { local label=$1; shift; case_ "$label" -- "$@"; }

COLLIDING=shoulder_pan_joint=0,shoulder_lift_joint=1.2,elbow_joint=0.3

# --- usage ------------------------------------------------------------------------------------
c "help" --help
c "version" --version
c "check help" check --help
c "areas help" areas --help
c "replay help" replay --help
c "run help" run --help
c "no subcommand"
c "unknown subcommand" frobnicate
c "unknown flag" check --bogus --joints elbow_joint=0
c "check without a state" check
c "--joints and --states" check --joints elbow_joint=0 --states cli/states.jsonl
c "--motion without --states" check --joints elbow_joint=0 --motion
c "bad --side" check --joints elbow_joint=0 --side sideways
c "areas without --thickness" areas areas/tri.obj
c "replay without a bag" replay
c "bad --pose-source" replay bags/small --pose-source bogus
c "--no-markers without --out" replay bags/small --no-markers

# --- check (tests/cli_check.rs) -----------------------------------------------------------------
c "check colliding, text" check --joints $COLLIDING
c "check colliding, json" check --joints $COLLIDING --json
c "check clear, text" check --joints shoulder_pan_joint=0
c "check out of limits, json" check --joints elbow_joint=3.0 --json
c "check out of limits, text" check --joints elbow_joint=3.0
c "states file, json (unknown joint warned)" check --states cli/states.jsonl --json
c "states file, text" check --states cli/states.jsonl
STDIN=cli/states.jsonl c "states from standard input" check --states - --json
c "wrist only, default thickness" check --params-file cli/wrist_only.yaml --states cli/behind.jsonl --json
c "wrist only, --thickness 0.2" check --params-file cli/wrist_only.yaml --states cli/behind.jsonl --json --thickness 0.2
c "wrist only, --thickness 0.005" check --params-file cli/wrist_only.yaml --states cli/behind.jsonl --json --thickness 0.005
c "wrist only, --side front" check --params-file cli/wrist_only.yaml --states cli/behind.jsonl --json --side front
c "wrist only, --side both" check --params-file cli/wrist_only.yaml --states cli/behind.jsonl --json --side both
c "transforms line placing one link of all: fails closed" check --states cli/behind.jsonl --json
c "bundled params file, json" check --params-file config/params.yaml --joints $COLLIDING --json
c "show params" check --show-params
c "show params, file and overrides" check --params-file config/params.yaml --thickness 0.05 --side both --show-params
c "show params, --srdf and --robot" check --srdf cli/arm.srdf --robot config/example_workcell/robot.urdf --show-params
c "--srdf, colliding" check --srdf cli/arm.srdf --joints $COLLIDING --json
c "--srdf, text" check --srdf cli/arm.srdf --joints $COLLIDING
c "--robot and --environment explicit" check --robot config/example_workcell/robot.urdf --environment config/example_workcell/environment.urdf --joints $COLLIDING --json
c "clearance threshold" check --params-file cli/clearance.yaml --joints $COLLIDING --json
c "clearance threshold, text" check --params-file cli/clearance.yaml --joints shoulder_pan_joint=0
c "padding" check --params-file cli/padding.yaml --joints shoulder_pan_joint=0,shoulder_lift_joint=1.0,elbow_joint=0.3 --json
c "random states, json" check --states cli/random.jsonl --json
c "random states, text" check --states cli/random.jsonl
c "random states, --motion json" check --states cli/random.jsonl --motion --json
c "path, --motion json" check --states cli/path.jsonl --motion --json
c "path, --motion text" check --states cli/path.jsonl --motion
c "transforms lines, json" check --states cli/tf.jsonl --json
c "transforms lines, --motion (fails closed)" check --states cli/tf.jsonl --motion --json

# --- check: bad input (tests/cli_check.rs, input_panics.rs) -------------------------------------
c "malformed URDF" check --robot cli/bad.urdf --joints a=0
c "unknown package" check --robot cli/pkg.urdf --joints a=0
c "missing mesh" check --robot cli/missing.urdf --joints a=0
c "NaN in a mesh" check --robot cli/nan.urdf --joints a=0
c "unknown parameter key" check --params-file cli/typo.yaml --joints elbow_joint=0
c "unknown joint in --joints" check --joints elbow_jiont=0.1
c "NaN in --joints" check --joints elbow_joint=nan
c "bad --joints syntax" check --joints elbow_joint
c "a line that is not a state" check --states cli/bad.jsonl
c "unequal lengths" check --states cli/unequal.jsonl
c "missing_joint: reject" check --params-file cli/reject.yaml --joints elbow_joint=0
c "package:// leaving its package" check --params-file cli/escape_params.yaml --robot cli/escape.urdf --joints j=0
c "missing states file" check --states cli/no_such_states.jsonl
c "missing parameters file" check --params-file cli/no_such.yaml --joints elbow_joint=0
c "missing robot file" check --robot cli/no_such.urdf --joints elbow_joint=0
c "tiny marker_rate" check --params-file cli/rate.yaml --joints elbow_joint=0
c "parallel arrays of different lengths" check --params-file cli/parallel_bad.yaml --joints elbow_joint=0
c "bad --thickness" check --joints elbow_joint=0 --thickness -1
c "run: tiny marker_rate" run --ros-args -p marker_rate:=1e-300
c "run: unknown parameter" run --ros-args -p no_such_key:=1
c "run: a group as a parameter" run --ros-args -p thin_surfaces:=1
c "run: unknown ROS argument" run --ros-args --bogus
case_ "run: ROS_DOMAIN_ID out of range" ROS_DOMAIN_ID=233 -- run

# --- areas (tests/cli_areas.rs) -----------------------------------------------------------------
c "binary STL with a solid header" areas areas/square.stl --thickness 0.01 --scale 2 --json work/square.json
for side in front both back; do
    c "OBJ, side $side" areas areas/tri.obj --thickness 0.02 --side $side --json work/tri_$side.json
done
c "guard sheet" areas config/example_workcell/guard_sheet.obj --thickness 0.03
c "guard sheet, json" areas config/example_workcell/guard_sheet.obj --thickness 0.03 --json work/cells.json
c "shelf, both" areas config/example_workcell/shelf.obj --thickness 0.02 --side both
c "bent panel, scale 3" areas config/example_workcell/bent_panel.obj --thickness 0.01 --scale 1,2,0.5
c "gripper (closed)" areas config/example_workcell/gripper.obj --thickness 0.005
c "OBJ with mixed face corners" areas areas/mixed_corners.obj --thickness 0.01
c "missing mesh" areas /nonexistent/mesh.stl --thickness 0.01
c "thickness 0" areas areas/tri.obj --thickness 0
c "thickness negative" areas areas/tri.obj --thickness -0.5
c "thickness NaN" areas areas/tri.obj --thickness NaN
c "scale of two" areas areas/tri.obj --thickness 0.01 --scale 1,2
c "garbage STL" areas areas/garbage.stl --thickness 0.01
c "NaN OBJ" areas areas/nan.obj --thickness 0.01
c "empty OBJ" areas areas/empty.obj --thickness 0.01
c "flat OBJ" areas areas/flat.obj --thickness 0.01
c "unsupported extension" areas areas/mesh.txt --thickness 0.01
CLOSED=1 c "closed standard output" areas areas/tri.obj --thickness 0.01
CLOSED=1 c "closed standard output, --json" areas areas/tri.obj --thickness 0.01 --json work/pipe.json
c "standard output full" areas areas/tri.obj --thickness 0.01 --json /dev/full

# --- hostile input (tests/hostile_input.rs) -----------------------------------------------------
hc() { local label=$1 robot=$2; shift 2; c "$label" check --robot "hostile/$robot" --json "$@"; }
hc "deep URDF" deep.urdf --joints j=0.3
hc "deep COLLADA" deep_dae.urdf --joints j=0.3
hc "entity bomb COLLADA" bomb_dae.urdf --joints j=0.3
hc "entity bomb URDF" bomb.urdf --joints j=0.3
for i in 0 1 2 3 4 5; do hc "size outside the range $i" huge_$i.urdf --joints j=0.3; done
for i in 0 1 2 3; do hc "largest sizes accepted $i" edge_$i.urdf --joints j=0.3; done
hc "--thickness 1e17" ok.urdf --joints j=0.3 --thickness 1e17
hc "--thickness 1e308" ok.urdf --joints j=0.3 --thickness 1e308
hc "axis 1e160" axis_big.urdf --joints j=0.7
hc "axis 1" axis_unit.urdf --joints j=0.7
hc "mesh a FIFO" fifo.urdf --joints j=0.3
hc "mesh /dev/zero" zero.urdf --joints j=0.3
hc "mesh of 2 GiB" sparse.urdf --joints j=0.3
hc "states /dev/zero" ok.urdf --states /dev/zero
hc "states a FIFO" ok.urdf --states hostile/states.jsonl
hc "material library a FIFO" mtl_mtl_pipe.mtl.urdf --joints j=0.3
hc "material library /dev/zero" mtl_mtl_zero.mtl.urdf --joints j=0.3
hc "URDF a FIFO" robot_pipe.urdf --joints j=0.3
c "parameters /dev/zero" check --params-file /dev/zero --joints elbow_joint=0
hc "good COLLADA" good_dae.urdf --joints j=0.3
for d in index_past stride_zero stride_huge missing_source count_huge array_count_huge; do hc "COLLADA $d" $d.urdf --joints j=0.3; done
hc "STL cut short" short_stl.urdf --joints j=0.3
for f in zero negative past; do hc "OBJ face index $f" face_$f.urdf --joints j=0.3; done
c "scale vanishing" areas hostile/tetra.obj --thickness 0.01 --scale 1e-300
c "scale overflowing" areas hostile/tetra.obj --thickness 0.01 --scale 1e308
hc "mimic multiplier NaN" mimic_nan.urdf --joints j=0.3
hc "mimic offset inf" mimic_inf.urdf --joints j=0.3
hc "limit NaN" limits_nan.urdf --joints j=0.3
hc "limits in the wrong order" limits_order.urdf --joints j=0.3
hc "joint twice in a state" ok.urdf --states hostile/dup.jsonl
hc "link twice in a transforms line" ok.urdf --states hostile/dup_tf.jsonl
hc "package:// up and out" escape_1.urdf --joints j=0.3 --params-file hostile/pkg_params.yaml
hc "package:// double slash" escape_2.urdf --joints j=0.3 --params-file hostile/pkg_params.yaml
hc "empty geometry" empty_geometry.urdf --joints j=0.3
hc "two shapes" two_shapes.urdf --joints j=0.3
hc "hex number" hex.urdf --joints j=0.3
hc "missing mesh through a URDF" missing_mesh.urdf --joints j=0.3
hc "100000 root links" roots.urdf --joints j=0.3
hc "state line of another shape" ok.urdf --states hostile/shape.jsonl
hc "state line with a BOM" ok.urdf --states hostile/bom.jsonl
c "YAML aliases" check --params-file hostile/alias.yaml --joints elbow_joint=0
c "YAML nested deep" check --params-file hostile/deep.yaml --joints elbow_joint=0

# --- real inputs (tests/real_inputs.rs) ---------------------------------------------------------
c "xacro URDF (panda)" check --robot fixtures/panda.urdf.xacro --joints panda_joint1=0
c "xacro URDF (fanuc)" check --robot fixtures/fanuc.urdf.xacro --joints panda_joint1=0
c "xacro under a plain name" check --robot real/panda_config.urdf --joints panda_joint1=0
PANDA=erd/robots/panda_description/urdf/panda.urdf
c "xacro SRDF" check --params-file real/panda.yaml --robot $PANDA --srdf fixtures/panda_arm.srdf.xacro --joints panda_joint1=0
c "expanded SRDF" check --params-file real/panda.yaml --robot $PANDA --srdf real/panda_arm.srdf --joints panda_joint1=0
c "expanded SRDF, json" check --params-file real/panda.yaml --robot $PANDA --srdf real/panda_arm.srdf --joints panda_joint1=0,panda_joint4=-2 --json
c "xacro SRDF, bundled arm" check --srdf fixtures/panda_arm.srdf.xacro --joints elbow_joint=0
for door in check replay run; do
    case $door in
        check) tail=(--joints j1=0) ;;
        replay) tail=() ;;
        run) tail=() ;;
    esac
    first=(check); [[ $door == replay ]] && first=(replay bags/j1_bag); [[ $door == run ]] && first=(run)
    c "$door: visual-only robot" "${first[@]}" --robot real/visual_only.urdf "${tail[@]}"
    c "$door: checked_links matching nothing" "${first[@]}" --params-file real/nothing.yaml "${tail[@]}"
done
c "visual geometry checked" check --params-file real/visual.yaml --robot real/visual_only.urdf --joints j1=0 --json
c "visual-only description in a bag" replay bags/arm_bag --jsonl work/arm.jsonl
c "states of another robot, check" check --states real/foreign.jsonl --json
c "states of another robot, replay" replay bags/panda_bag --jsonl work/panda.jsonl
c "last waits: split state" check --states real/split.jsonl --json
c "last waits: whole state" check --states real/whole.jsonl --json
c "last waits: upper arm only" check --states real/split.jsonl --json --params-file real/upper.yaml
c "missing_joint zero" check --states real/split.jsonl --json --params-file real/zero.yaml
c "SRDF for the recorded robot" replay bags/r2_bag --srdf real/r2.srdf
c "SRDF fitting neither" replay bags/r2_bag --srdf real/wrong.srdf
c "SRDF of the recorded robot, check" check --srdf real/r2.srdf --joints elbow_joint=0
cp "$BIN" "$IN/prefix/bin/thickness_collision"
EXE=prefix/bin/thickness_collision NOCONFIG=1 c "installed binary finds its workcell" check --joints $COLLIDING --json

# --- replay (tests/replay_bags.rs, replay_compressed.rs, hostile_input.rs) ------------------------
for s in mcap sqlite3; do
    c "replay $s, text" replay bags/js_$s --no-motion
    c "replay $s, jsonl and out" replay bags/js_$s --no-motion --jsonl work/out.jsonl --out work/out_bag
    c "replay $s, motion" replay bags/js_$s --motion --jsonl work/motion.jsonl
    c "replay $s, default motion" replay bags/js_$s --jsonl work/default.jsonl
    c "replay $s, tf" replay bags/tf_$s --pose-source tf --no-motion --jsonl work/tf.jsonl
    c "replay $s, tf motion" replay bags/tf_$s --pose-source tf --motion --jsonl work/tf_motion.jsonl
    c "replay $s, an undecodable message" replay bags/undecodable_$s --no-motion --jsonl work/und.jsonl
done
c "replay, plot" replay bags/js_mcap --no-motion --plot work/timeline.svg
c "replay, out without markers" replay bags/js_mcap --no-motion --out work/bag --no-markers
c "replay, window" replay bags/js_mcap --no-motion --start 0.5 --end 1.5 --jsonl work/window.jsonl
c "replay, bare mcap" replay bags/bare_js_mcap.mcap --no-motion --jsonl work/bare.jsonl
c "replay, bare db3" replay bags/bare_js_sqlite3.db3 --no-motion --jsonl work/bare.jsonl
c "replay, parameters and overrides" replay bags/js_mcap --params-file config/params.yaml --thickness 0.05 --side both --no-motion --jsonl work/o.jsonl
c "replay, clearance" replay bags/small --params-file cli/clearance.yaml --jsonl work/c.jsonl
c "replay, description from the bag" replay bags/desc --no-motion --jsonl work/desc.jsonl
c "replay, truncated mcap" replay bags/cut --no-motion --jsonl work/cut.jsonl
c "replay, corrupt db3" replay bags/corrupt_db --no-motion
c "replay, not a bag" replay bags/notes.txt --no-motion
c "replay, missing bag" replay bags/nothing_here.mcap --no-motion
c "replay, absent topic" replay bags/small --topic /arm/joint_states --no-motion
c "replay, --start NaN" replay bags/plain_bag --start nan
c "replay, --start inf" replay bags/plain_bag --start inf
c "replay, --start after --end" replay bags/plain_bag --start 3 --end 1
c "replay, --topic of another type" replay bags/plain_bag --topic /tf
c "replay, jsonl to a full disk" replay bags/plain_bag --jsonl /dev/full
c "replay, a file listed twice" replay bags/twice_bag
c "replay, deep description" replay bags/deep_bag --jsonl work/deep.jsonl
c "replay, plain" replay bags/plain_bag --jsonl work/plain.jsonl
for s in mcap sqlite3; do
    for mode in message file; do
        c "replay $s, compression $mode" replay bags/${mode}_$s --no-motion --jsonl work/z.jsonl
        c "replay $s, compression $mode by rosbags" replay bags/rosbags_${mode}_$s --no-motion --jsonl work/z.jsonl
    done
    c "replay $s, corrupt zstd file" replay bags/file_cut_$s --no-motion --jsonl work/z.jsonl
    c "replay $s, junk messages" replay bags/junk_$s --no-motion --jsonl work/z.jsonl
    c "replay $s, one good message among junk" replay bags/mixed_$s --no-motion --jsonl work/z.jsonl
done
c "replay, bare .mcap.zstd" replay bags/bare_file_mcap.mcap.zstd --no-motion --jsonl work/z.jsonl
c "replay, bare .db3.zstd" replay bags/bare_file_sqlite3.db3.zstd --no-motion --jsonl work/z.jsonl
c "replay, bare message-compressed mcap" replay bags/bare_message_mcap.mcap --no-motion --jsonl work/z.jsonl
c "replay, bare message-compressed db3" replay bags/bare_message_sqlite3.db3 --no-motion --jsonl work/z.jsonl
c "replay, ROS 1 channel" replay bags/ros1 --no-motion
c "replay, lz4" replay bags/lz4 --no-motion
c "replay, the one message junk" replay bags/one_junk --no-motion
c "replay, topic without messages" replay bags/tf_only --no-motion
c "replay, every message outside the window" replay bags/cplain --no-motion --start 100
c "replay, inside the window" replay bags/cplain --no-motion --start 0.015 --jsonl work/w.jsonl

# --- more edges -------------------------------------------------------------------------------
c "robot with no actuated joint, --joints" check --robot cli/fixed.urdf --joints f=0 --json
c "robot with no actuated joint, --states" check --robot cli/fixed.urdf --states cli/fixed.jsonl --json
c "rcl sections merged, show params" check --params-file cli/sections.yaml --show-params
c "rcl sections merged, check" check --params-file cli/sections.yaml --joints $COLLIDING --json
c "areas, COLLADA" areas hostile/good.dae --thickness 0.01 --json work/dae.json
for m in meta_bad_yaml meta_no_paths meta_escape meta_unknown_storage meta_missing_file meta_bad_mode empty_dir; do
    c "replay, $m" replay bags/$m --no-motion
done
c "replay, garbage .mcap" replay bags/garbage.mcap --no-motion
c "replay, garbage .db3" replay bags/garbage.db3 --no-motion
c "replay, garbage .mcap.zstd" replay bags/garbage.mcap.zstd --no-motion
c "replay, --out exists" replay bags/small --no-motion --out exists/bag
c "replay, --out cannot be made" replay bags/small --no-motion --out /dev/null/bag
c "replay, --jsonl cannot be made" replay bags/small --no-motion --jsonl /dev/null/x.jsonl
c "replay, --plot cannot be made" replay bags/small --no-motion --plot /dev/null/x.svg
c "replay, --plot to a full disk" replay bags/small --no-motion --plot /dev/full
c "replay, tf with a frame prefix nobody uses" replay bags/tf_mcap --pose-source tf --frame-prefix robot1/ --no-motion --jsonl work/p.jsonl
c "replay, tf source on a joint-state bag" replay bags/small --pose-source tf --no-motion
c "replay, joint_states topic as tf" replay bags/small --pose-source tf --topic /joint_states --no-motion
c "replay, everything at once" replay bags/js_sqlite3 --motion --start 0.2 --end 2.2 --thickness 0.03 --side front --srdf cli/arm.srdf --jsonl work/all.jsonl --plot work/all.svg --out work/all_bag

echo "$n invocations in $OUT"
