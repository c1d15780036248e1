#!/usr/bin/env python3
"""The library's public surface, counted as rustdoc sees it.

    python3 scripts/public_items.py [--list] [--features F] [--json FILE]

Builds the rustdoc JSON of the library with nightly (`cargo +nightly rustdoc --lib -- -Z
unstable-options --output-format json`, default features: `parallel` and `ros`; `--features
testing` adds the fixtures the tests see) and walks it from the crate root. What counts:

- an *item* is a name a user of the crate can reach by a public path: a module (the crate root
  aside), struct, enum, union, trait, function, constant, static, type alias or macro of this
  crate, each counted once however many paths lead to it (a `pub use` of one is followed to it);
  a `pub use` of another crate's item (`math::Pose`) counts as one item of ours;
- an *associated item* is a name reached through an item: an associated function, constant or
  type of an inherent `impl` (`Checker::check_joints`), an item of a trait;
- *fields and variants*: the public fields of a struct or of an enum variant, and the variants;
  counted apart, since they follow from the data a type carries (a ROS message has its fields);
- not counted: trait implementations (`impl Display for ...`, derives: their names are the
  trait's), `#[doc(hidden)]` items (rustdoc leaves them out: `fuzz_access`), private items and
  `pub` items no public path reaches (in a private module and re-exported by no `mod.rs`).

The measure is "public items" = items + associated items, printed per layer (the crate root's
modules) with the fields and variants beside. `--list` prints every name with its path and kind.
`--json FILE` reads a rustdoc JSON file instead of building one (its feature set is then the
file's). The build goes to `$CARGO_TARGET_DIR` (default `target/`), under its own toolchain's
hashes, so it leaves the stable build's artefacts alone.
"""
import argparse
import collections
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ITEM_KINDS = {"module", "struct", "enum", "union", "trait", "function", "constant", "static", "type_alias", "macro", "trait_alias"}


def build_json(features):
    cmd = ["cargo", "+nightly", "rustdoc", "--lib", "--locked"]
    if features:
        cmd += ["--features", features]
    cmd += ["--", "-Z", "unstable-options", "--output-format", "json"]
    subprocess.run(cmd, cwd=ROOT, check=True)
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "doc" / "thickness_collision.json"


def kind_of(item):
    (kind,) = item["inner"].keys()
    return kind


class Walk:
    def __init__(self, doc):
        self.index = doc["index"]
        self.paths = doc.get("paths", {})
        self.items = {}  # id -> (path, kind)
        self.members = []  # (path, kind)

    def get(self, id_):
        return self.index.get(str(id_))

    def add_member(self, path, kind):
        self.members.append((path, kind))

    def module(self, item, path):
        for child_id in item["inner"]["module"]["items"]:
            child = self.get(child_id)
            if child is None:
                continue
            self.visit(child, path)

    def visit(self, item, parent, name=None):
        """Counts `item`, reached as `parent::name` (its own name unless a `pub use` renames it)."""
        if kind_of(item) != "use":
            return self.visit_item(item, parent, name)
        use = item["inner"]["use"]
        target = self.get(use["id"]) if use.get("id") is not None else None
        if target is not None and target.get("crate_id") == 0:
            if not use.get("is_glob"):
                self.visit(target, parent, use["name"])
            elif kind_of(target) == "module":
                self.module(target, parent)
        elif not use.get("is_glob"):
            self.record(("use", use["source"]), f"{parent}::{use['name']}", "re-export")

    def record(self, key, path, kind):
        if key in self.items:
            return False
        self.items[key] = (path, kind)
        return True

    def visit_item(self, item, parent, name=None):
        kind = kind_of(item)
        name = name or item["name"]
        path = f"{parent}::{name}"
        if kind not in ITEM_KINDS:
            return
        if item.get("crate_id") != 0:
            # Another crate's item inlined into ours by a `pub use`: one name of our API.
            self.record(item["id"], path, "re-export")
            return
        if not self.record(item["id"], path, kind):
            return
        inner = item["inner"][kind]
        if kind == "module":
            self.module(item, path)
        elif kind == "struct":
            self.struct_fields(inner["kind"], path)
            self.impls(inner.get("impls", []), path)
        elif kind == "union":
            for f in inner.get("fields", []):
                self.field(f, path)
            self.impls(inner.get("impls", []), path)
        elif kind == "enum":
            for v in inner["variants"]:
                variant = self.get(v)
                if variant is None:
                    continue
                vpath = f"{path}::{variant['name']}"
                self.add_member(vpath, "variant")
                vkind = variant["inner"]["variant"]["kind"]
                if isinstance(vkind, dict) and "tuple" in vkind:
                    for i, f in enumerate(vkind["tuple"]):
                        if f is not None:
                            self.add_member(f"{vpath}.{i}", "field")
                elif isinstance(vkind, dict) and "struct" in vkind:
                    for f in vkind["struct"]["fields"]:
                        self.field(f, vpath)
            self.impls(inner.get("impls", []), path)
        elif kind == "trait":
            for t in inner["items"]:
                titem = self.get(t)
                if titem is not None:
                    self.add_member(f"{path}::{titem['name']}", "trait " + kind_of(titem))

    def struct_fields(self, skind, path):
        if isinstance(skind, dict) and "plain" in skind:
            for f in skind["plain"]["fields"]:
                self.field(f, path)
        elif isinstance(skind, dict) and "tuple" in skind:
            for i, f in enumerate(skind["tuple"]):
                if f is not None:
                    self.add_member(f"{path}.{i}", "field")

    def field(self, id_, path):
        f = self.get(id_)
        if f is not None:
            self.add_member(f"{path}.{f['name']}", "field")

    def impls(self, ids, path):
        for i in ids:
            imp = self.get(i)
            if imp is None:
                continue
            inner = imp["inner"]["impl"]
            if inner.get("trait") is not None or inner.get("is_synthetic") or inner.get("blanket_impl") is not None:
                continue
            for a in inner["items"]:
                assoc = self.get(a)
                if assoc is None or assoc.get("visibility") != "public":
                    continue
                self.add_member(f"{path}::{assoc['name']}", kind_of(assoc))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--list", action="store_true", help="print every item and member")
    ap.add_argument("--features", default="", help="cargo features besides the default ones")
    ap.add_argument("--json", type=Path, help="a rustdoc JSON file to read instead of building")
    args = ap.parse_args()
    path = args.json or build_json(args.features)
    doc = json.loads(path.read_text())
    root = doc["index"][str(doc["root"])]
    walk = Walk(doc)
    walk.module(root, "crate")

    # Per layer (the crate root's modules): items, associated items, fields and variants.
    columns = ("items", "associated", "fields+variants")
    counts = collections.defaultdict(collections.Counter)
    kinds = collections.Counter()
    listed = []
    for p, k in walk.items.values():
        counts[p.split("::")[1]]["items"] += 1
        kinds[k] += 1
        listed.append((p, k))
    for p, k in walk.members:
        column = "fields+variants" if k in ("field", "variant") else "associated"
        counts[p.split("::")[1].split(".")[0]][column] += 1
        kinds[k] += 1
        listed.append((p, k))
    if args.list:
        for p, k in sorted(listed):
            print(f"{k:16} {p}")
        print()
    print(f"{'layer':12}" + "".join(f"{c:>17}" for c in columns))
    total = collections.Counter()
    for layer in sorted(counts):
        total.update(counts[layer])
        print(f"{layer:12}" + "".join(f"{counts[layer][c]:17}" for c in columns))
    print(f"{'all':12}" + "".join(f"{total[c]:17}" for c in columns))
    print("by kind: " + ", ".join(f"{k} {n}" for k, n in sorted(kinds.items(), key=lambda kv: -kv[1])))
    print(f"public items: {total['items'] + total['associated']} (items {total['items']} + associated {total['associated']}); "
          f"with fields and variants: {sum(total.values())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
