#!/usr/bin/env python3
"""The house rules, measured: functions over 80 lines, files over 500 lines, import circles.

    python3 scripts/house_check.py [SRC_DIR ...]     (default: src)

Rules (what docs/house.md calls the measures):
- a function runs from its `fn` line to its closing brace, blank and comment lines included;
- tests are exempt: a file's lines from its first `#[cfg(test)]` on, and files named `*_tests.rs`;
- an import circle is a cycle of files in which each names, by a `use crate::` / `use super::`
  path, an item defined in the next; a re-export through `mod.rs` / `lib.rs` is followed to the
  file that defines the item, and does not count as an edge itself.

Exit 1 when a rule fails, listing every failure; 0 otherwise. Text-level parsing: strings, chars
and comments are masked before braces are counted, which is enough for rustfmt-formatted code.
"""
import re
import sys
from pathlib import Path

MAX_FN = 80
MAX_FILE = 500
ITEM_RE = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:unsafe\s+|async\s+|const\s+|extern\s+\"C\"\s+)*"
                     r"(?:fn|struct|enum|trait|type|const|static|union|mod|macro_rules!)\s+([A-Za-z_][A-Za-z0-9_]*)")
FN_RE = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:default\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?(?:extern\s+\"[^\"]*\"\s+)?fn\s+([A-Za-z_][A-Za-z0-9_]*)")


def mask(text):
    """Code with comments, strings and char literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            hashes = re.match(r"r(#*)\"", text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            j = n if end < 0 else end + 1 + len(hashes)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(re.sub(r"[^\n]", " ", text[i:j + 1]))
            i = j + 1
        elif c == "'":
            m = re.match(r"'(\\.|\\u\{[0-9a-fA-F]+\}|\\x[0-9a-fA-F]{2}|[^\\'])'", text[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:  # a lifetime
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def code_lines(path):
    """The file's lines before its first `#[cfg(test)]` (all of them for non-test files)."""
    lines = path.read_text().split("\n")
    if path.name.endswith("_tests.rs"):
        return []
    for k, line in enumerate(lines):
        if line.strip().startswith("#[cfg(test)]"):
            return lines[:k]
    return lines


def long_functions(path):
    lines = mask("\n".join(code_lines(path))).split("\n")
    found = []
    for k, line in enumerate(lines):
        m = FN_RE.match(line)
        if not m:
            continue
        depth, started = 0, False
        for j in range(k, len(lines)):
            for ch in lines[j]:
                if ch == "{":
                    depth, started = depth + 1, True
                elif ch == "}":
                    depth -= 1
                elif ch == ";" and not started and depth == 0:
                    break  # a declaration without a body
            else:
                if started and depth == 0:
                    if j - k + 1 > MAX_FN:
                        found.append((m.group(1), k + 1, j - k + 1))
                    break
                continue
            break
    return found


def module_of(src, path):
    rel = path.relative_to(src).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return parts


def defined_items(path):
    items = set()
    for line in mask("\n".join(code_lines(path))).split("\n"):
        m = ITEM_RE.match(line)
        if m:
            items.add(m.group(1))
    return items


def use_paths(path):
    """(path segments, item) for every name a `use crate::`/`use super::`/`use self::` brings in."""
    text = mask("\n".join(code_lines(path)))
    out = []
    for m in re.finditer(r"\buse\s+((?:crate|super|self)(?:::[^;]+)?);", text, re.S):
        spec = re.sub(r"\s+", "", m.group(1))
        out.extend(expand(spec))
    return out


def expand(spec):
    """`a::b::{c, d::e}` to [[a, b, c], [a, b, d, e]]."""
    if "{" not in spec:
        segs = spec.split("::")
        segs[-1] = segs[-1].split("as")[0] if re.match(r".+as[A-Za-z_]", segs[-1]) and " " in segs[-1] else segs[-1]
        return [segs]
    head, rest = spec.split("{", 1)
    inner = rest[:rest.rfind("}")]
    parts, depth, cur = [], 0, ""
    for ch in inner:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += ch == "{"
        depth -= ch == "}"
        cur += ch
    parts.append(cur)
    out = []
    for p in filter(None, parts):
        out.extend(expand(head + p))
    return out


def resolve(src, files, mods, here, segs):
    """The file that defines the item `segs` names, seen from module `here`."""
    base = list(here)
    segs = list(segs)
    if segs[0] == "crate":
        base, segs = [], segs[1:]
    while segs and segs[0] in ("super", "self"):
        if segs[0] == "super":
            base = base[:-1]
        segs = segs[1:]
    if not segs:
        return None
    item = re.sub(r"as\w+$", "", segs[-1]) if "as" in segs[-1] else segs[-1]
    if item in ("*", "self"):
        return None
    modpath = base + segs[:-1]
    # The item may itself be a module: that file is the target.
    whole = tuple(modpath + [item])
    if whole in mods:
        return mods[whole]
    # Follow re-exports: the defining file somewhere under the module.
    prefix = tuple(modpath)
    owners = [f for f in files if tuple(module_of(src, f))[:len(prefix)] == prefix and item in defined_items(f)]
    if len(owners) == 1:
        return owners[0]
    exact = [f for f in owners if tuple(module_of(src, f)) == prefix]
    return exact[0] if exact else (owners[0] if owners else None)


def circles(src, files):
    mods = {tuple(module_of(src, f)): f for f in files}
    graph = {f: set() for f in files}
    for f in files:
        here = module_of(src, f)
        for segs in use_paths(f):
            target = resolve(src, files, mods, here, segs)
            if target is not None and target != f and target.name not in ("mod.rs", "lib.rs"):
                graph[f].add(target)
    # Tarjan's strongly connected components.
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(comp)

    sys.setrecursionlimit(10_000)
    for v in files:
        if v not in index:
            visit(v)
    return comps


def main(args):
    roots = [Path(a) for a in args] or [Path("src")]
    bad = 0
    for src in roots:
        files = sorted(p for p in src.rglob("*.rs"))
        for f in files:
            n = len(code_lines(f))
            if n > MAX_FILE:
                print(f"file over {MAX_FILE} lines: {f} ({n})")
                bad += 1
            for name, line, length in long_functions(f):
                print(f"function over {MAX_FN} lines: {f}:{line} {name} ({length})")
                bad += 1
        for comp in circles(src, files):
            print(f"import circle of {len(comp)} files: " + " ".join(str(p.relative_to(src)) for p in sorted(comp)))
            bad += 1
    print(f"{bad} failure(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
