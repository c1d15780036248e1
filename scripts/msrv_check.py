#!/usr/bin/env python3
"""The crate's declared `rust-version` against the locked dependencies': fails when a dependency
needs a newer Rust than the crate says it builds with (the declaration would send users with that
toolchain into a dependency's error instead of cargo's). Only a toolchain of that version could
check the crate's own code; clippy's `incompatible_msrv` covers its standard library calls."""
import json
import subprocess
import sys


def version(v):
    parts = [int(x) for x in v.split(".")]
    return tuple(parts + [0] * (3 - len(parts)))


meta = json.loads(subprocess.run(["cargo", "metadata", "--format-version", "1", "--locked"], check=True, capture_output=True, text=True).stdout)
members = set(meta["workspace_members"])
nodes = {n["id"]: n for n in meta["resolve"]["nodes"]}
packages = {p["id"]: p for p in meta["packages"]}
failures = 0
for member in (p for p in meta["packages"] if p["id"] in members):
    declared = member.get("rust_version")
    if not declared:
        continue
    # Every package the member depends on, transitively, normal and build dependencies.
    seen, todo = set(), [member["id"]]
    while todo:
        node = nodes[todo.pop()]
        for dep in node["deps"]:
            if any(k["kind"] in (None, "build") for k in dep["dep_kinds"]) and dep["pkg"] not in seen:
                seen.add(dep["pkg"])
                todo.append(dep["pkg"])
    needs = [(packages[i]["rust_version"], packages[i]["name"], packages[i]["version"]) for i in seen if packages[i].get("rust_version")]
    newest = max(needs, key=lambda n: version(n[0]), default=None)
    if newest and version(newest[0]) > version(declared):
        print(f"{member['manifest_path']}: rust-version {declared}, but {newest[1]} {newest[2]} needs {newest[0]} (allowed: at least {newest[0]})")
        failures += 1
    else:
        print(f"{member['name']}: rust-version {declared}; newest need among {len(seen)} dependencies: {newest[1] + ' ' + newest[0] if newest else 'none'}")
sys.exit(1 if failures else 0)
