"""Shared fixtures: the Panda of example-robot-data in the bundled workcell's environment, and
the CLI (`TC_BIN`, set by tests/python_package.rs) for `check --json`."""

import json
import os
import pathlib
import site
import subprocess

import pytest

import thickness_collision as tc

ROOT = pathlib.Path(__file__).resolve().parents[2]


def erd_share():
    for p in site.getsitepackages():
        share = pathlib.Path(p) / "cmeel.prefix" / "share"
        if (share / "example-robot-data").is_dir():
            return share
    pytest.fail("example-robot-data is not installed (scripts/setup_venv.sh)")


@pytest.fixture(scope="session")
def panda_urdf():
    share = erd_share()
    os.environ["ROS_PACKAGE_PATH"] = str(share)
    return share / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf"


@pytest.fixture(scope="session")
def environment_urdf():
    return ROOT / "config" / "example_workcell" / "environment.urdf"


@pytest.fixture(scope="session")
def panda_params(panda_urdf, environment_urdf, tmp_path_factory):
    """The Panda with its SRDF, 5 mm above the workcell's table, as the node reads it."""
    srdf = panda_urdf.parents[1] / "srdf" / "panda.srdf"
    path = tmp_path_factory.mktemp("params") / "panda.yaml"
    path.write_text(
        "/**/thickness_collision:\n  ros__parameters:\n"
        f"    robot_description_file: {panda_urdf}\n    environment_file: {environment_urdf}\n"
        f"    robot_semantic_file: {srdf}\n    robot_base_pose: [0.0, 0.0, 0.005, 0.0, 0.0, 0.0]\n"
    )
    return path


@pytest.fixture(scope="session")
def panda(panda_params):
    return tc.Checker.from_params(panda_params)


def cli_json(args, lines):
    """`check --json` over a states file of `lines`: one object per line."""
    binary = os.environ.get("TC_BIN")
    if not binary:
        pytest.fail("TC_BIN: the thickness_collision binary (tests/python_package.rs sets it)")
    states = ROOT / "target" / f"pytest_states_{os.getpid()}.jsonl"
    states.write_text("".join(json.dumps(l) + "\n" for l in lines))
    try:
        out = subprocess.run([binary, "check", *args, "--states", str(states), "--json"], capture_output=True, text=True, check=True)
    finally:
        states.unlink()
    return [json.loads(l) for l in out.stdout.splitlines() if l.strip()]
