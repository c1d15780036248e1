"""Cyclone DDS IDL types parsed from ROS 2 .msg/.srv definition files, for peers whose types must
come from the interfaces' own definitions rather than from hand-written field lists (scene_peer.py
uses moveit_msgs this way). The files are vendored under tests/fixtures/msg_definitions/
(<pkg>/msg/<Type>.msg, <pkg>/srv/<Type>.srv; their origin is in the README there).

Parsing follows the ROS 2 .msg grammar as far as these files need it: one "TYPE NAME [DEFAULT]"
field per line; "TYPE NAME=VALUE" constants (skipped: they do not travel); "#" comments (outside
quoted strings); TYPE a primitive, "Type" (same package), "pkg/Type" or "pkg/msg/Type", "Header"
(std_msgs/Header), with "string<=N" bounded strings and "[]" (sequence), "[<=N]" (bounded
sequence) or "[N]" (fixed array) suffixes. A .srv is a request and a response split by "---".

Types are named as ROS 2 names them on DDS (pkg::msg::dds_::Type_, pkg::srv::dds_::Type_Request_),
annotated as tests/peers/moveit_types.py and dds_types.py do: t.sequence[T] for T[], t.sequence[T, N]
for T[<=N], t.array[T, N] for T[N], t.bounded_str[N] for string<=N, t.byte for byte, uint8 for char.

API (type names are "pkg/msg/Type", "pkg/srv/Type_Request" / "_Response"; "pkg/Type" means msg):
  idl(name)              the IdlStruct class
  service(name)          (Request, Response) classes of "pkg/srv/Type", the .srv's fields only
                         (the "enhanced" mapping)
  cyclone_service(name)  the same with Cyclone's request/reply header, a uint64 guid and an int64
                         seq before the fields (RustDDS's "cyclone" service mapping, as in
                         moveit_types.Request / dds_types._with_header and service_client.py)
  definition(name)       the parsed fields: [Field(name, base, kind, n, str_bound, default)]
  from_json(name, value) a message from a JSON-like dict keyed by field names; a missing field
                         takes the default the .msg gives it, else zero / "" / False / [] (fixed
                         arrays: N zeros) / a nested message built from {}; unknown keys are an
                         error; float fields also accept "NaN", "inf", "-inf". `make` and
                         `prim_seq` hooks build other classes (scene_peer.py builds rosbags ones)
  to_json(msg)           the inverse for any dataclass message (Cyclone or rosbags): dicts, lists,
                         numbers, strings, bools; non-finite floats as "NaN" / "inf" / "-inf"
"""
import dataclasses
import math
import re
import types
from dataclasses import dataclass
from pathlib import Path

from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t

DEFS = Path(__file__).resolve().parents[1] / "fixtures" / "msg_definitions"

# ROS 2 primitive -> Cyclone annotation (rosidl maps byte to octet and char to uint8).
PRIMS = {"bool": bool, "byte": t.byte, "char": t.uint8, "int8": t.int8, "uint8": t.uint8, "int16": t.int16, "uint16": t.uint16,
         "int32": t.int32, "uint32": t.uint32, "int64": t.int64, "uint64": t.uint64, "float32": t.float32, "float64": t.float64,
         "string": str}
INTS = {"byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"}
FLOATS = {"float32", "float64"}


@dataclass
class Field:
    name: str
    base: str        # a primitive ("float64", "string"...) or a full message name "pkg/msg/Type"
    kind: str        # "one", "seq" (T[]), "bseq" (T[<=N]) or "array" (T[N])
    n: int           # the bound or length (0 for "one" and "seq")
    str_bound: int   # N of string<=N, else 0
    default: object  # the .msg default (already converted), or None


def struct_typed(ros_type, fields):
    """An IDL struct named as ROS 2 names DDS types: pkg::msg::dds_::Type_ (as dds_types.py)."""
    pkg, kind, name = ros_type.split("/")
    cls = types.new_class(name, (IdlStruct,), {"typename": f"{pkg}::{kind}::dds_::{name}_"},
                          lambda ns: ns.update({"__annotations__": dict(fields)}))
    return dataclass(cls)


def canonical(name):
    """'pkg/Type' -> 'pkg/msg/Type'; 'pkg/msg/Type' and 'pkg/srv/Type_Request' unchanged."""
    parts = name.split("/")
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    if len(parts) == 3:
        return name
    raise ValueError(f"bad type name {name!r}")


def _strip_comment(line):
    """The line without its "#" comment; a "#" inside a quoted string is kept."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            return line[:i]
    return line


def _scalar(base, text):
    """A default value's literal for a primitive."""
    text = text.strip()
    if base == "bool":
        if text.lower() in ("true", "1"):
            return True
        if text.lower() in ("false", "0"):
            return False
        raise ValueError(f"bad bool {text!r}")
    if base in INTS:
        return int(text, 0)
    if base in FLOATS:
        return float(text)
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "\"'":
        return text[1:-1].encode().decode("unicode_escape")
    return text


def _default(base, kind, text):
    """A field's default value from its .msg literal ("[1, 2]" for arrays)."""
    if kind == "one":
        return _scalar(base, text)
    body = text.strip()
    if not (body.startswith("[") and body.endswith("]")):
        raise ValueError(f"bad array default {text!r}")
    items = re.findall(r"\"(?:[^\"\\]|\\.)*\"|'(?:[^'\\]|\\.)*'|[^,\s][^,]*", body[1:-1])
    return [_scalar(base, x) for x in items]


def parse(text, pkg):
    """The fields of one .msg text (or one half of a .srv) in package `pkg`."""
    fields = []
    for raw in text.splitlines():
        line = _strip_comment(raw).strip()
        if not line:
            continue
        ty, rest = (line.split(None, 1) + [""])[:2]
        m = re.fullmatch(r"([A-Za-z][A-Za-z0-9_]*)\s*(=)?\s*(.*)", rest)
        if m is None:
            raise ValueError(f"{pkg}: bad line {raw!r}")
        fname, is_const, value = m.groups()
        if is_const:
            continue  # a constant: not on the wire
        tm = re.fullmatch(r"([A-Za-z][A-Za-z0-9_/]*)(?:<=(\d+))?(?:\[(<=)?(\d*)\])?", ty)
        if tm is None:
            raise ValueError(f"{pkg}: bad type {ty!r}")
        base, sbound, bounded, n = tm.groups()
        if "[" not in ty:
            kind, n = "one", 0
        elif n == "":
            kind, n = "seq", 0
        else:
            kind, n = ("bseq" if bounded else "array"), int(n)
        if base not in PRIMS:
            if base == "Header":
                base = "std_msgs/msg/Header"
            elif "/" in base:
                base = canonical(base)
            else:
                base = f"{pkg}/msg/{base}"
        elif sbound and base != "string":
            raise ValueError(f"{pkg}: bound on a non-string {ty!r}")
        default = _default(base, kind, value) if value else None
        fields.append(Field(fname, base, kind, n, int(sbound or 0), default))
    return fields


def source(name):
    """The vendored file of a message, or of a service for "pkg/srv/Type[_Request|_Response]"."""
    pkg, kind, typ = canonical(name).split("/")
    if kind == "srv":
        typ = re.sub(r"_(Request|Response)$", "", typ)
    return DEFS / pkg / kind / f"{typ}.{kind}"


_FIELDS = {}
_TYPES = {}


def definition(name):
    """The parsed fields of a message ("pkg/msg/Type") or service half ("pkg/srv/Type_Request")."""
    name = canonical(name)
    if name not in _FIELDS:
        pkg, kind, typ = name.split("/")
        text = source(name).read_text()
        if kind == "srv":
            parts = re.split(r"^\s*---\s*$", text, flags=re.M)
            if len(parts) != 2 or not typ.endswith(("_Request", "_Response")):
                raise ValueError(f"bad service part {name}")
            text = parts[0] if typ.endswith("_Request") else parts[1]
        _FIELDS[name] = parse(text, pkg)
    return _FIELDS[name]


def _annotation(f):
    """The Cyclone annotation of a field."""
    if f.base in PRIMS:
        one = t.bounded_str[f.str_bound] if f.str_bound else PRIMS[f.base]
    else:
        one = idl(f.base)
    if f.kind == "one":
        return one
    if f.kind == "seq":
        return t.sequence[one]
    if f.kind == "bseq":
        return t.sequence[one, f.n]
    return t.array[one, f.n]


def idl(name):
    """The Cyclone IdlStruct of a message or service half, built (with what it uses) on first use."""
    name = canonical(name)
    if name not in _TYPES:
        _TYPES[name] = struct_typed(name, [(f.name, _annotation(f)) for f in definition(name)])
    return _TYPES[name]


def service(name):
    """(Request, Response) of "pkg/srv/Type" with the .srv's fields only."""
    return idl(f"{name}_Request"), idl(f"{name}_Response")


_CYCLONE = {}


def cyclone_service(name):
    """(Request, Response) of "pkg/srv/Type" with Cyclone's (guid, seq) header first."""
    if name not in _CYCLONE:
        header = [("guid", t.uint64), ("seq", t.int64)]
        _CYCLONE[name] = tuple(struct_typed(f"{name}_{part}", header + list(idl(f"{name}_{part}").__annotations__.items()))
                               for part in ("Request", "Response"))
    return _CYCLONE[name]


def _prim(base, x, str_bound=0):
    """A JSON value converted to a primitive field's Python value."""
    if base == "bool":
        if not isinstance(x, (bool, int)):
            raise ValueError(f"bool expected, got {x!r}")
        return bool(x)
    if base in INTS:
        if isinstance(x, float) and not x.is_integer():
            raise ValueError(f"{base} expected, got {x!r}")
        return int(x)
    if base in FLOATS:
        if isinstance(x, str):
            return {"nan": math.nan, "inf": math.inf, "-inf": -math.inf, "infinity": math.inf, "-infinity": -math.inf}[x.lower()]
        return float(x)
    if not isinstance(x, str):
        raise ValueError(f"string expected, got {x!r}")
    if str_bound and len(x.encode()) > str_bound:
        raise ValueError(f"string longer than {str_bound}: {x!r}")
    return x


def _zero(base):
    return {"bool": False, "string": ""}.get(base, 0.0 if base in FLOATS else 0)


def _cyclone_make(name, kwargs):
    return idl(name)(**kwargs)


def from_json(name, value, make=None, prim_seq=None):
    """A message of type `name` from `value`, a dict keyed by field names (see the module doc).
    `make(name, kwargs)` builds a message (default: this module's IDL class); `prim_seq(base, list)`
    turns a sequence or array of primitives into what `make` wants (default: the list as is)."""
    name = canonical(name)
    make = make or _cyclone_make
    value = {} if value is None else value
    if not isinstance(value, dict):
        raise ValueError(f"{name}: a dict expected, got {value!r}")
    fields = definition(name)
    unknown = set(value) - {f.name for f in fields}
    if unknown:
        raise ValueError(f"{name}: unknown fields {sorted(unknown)}")
    kwargs = {}
    for f in fields:
        x = value.get(f.name)
        x = f.default if x is None else x  # missing (or null): the .msg default, else zero below
        if f.base in PRIMS:
            def one(v, f=f):
                return _prim(f.base, v, f.str_bound)
        else:
            def one(v, f=f):
                return from_json(f.base, v, make, prim_seq)
        if f.kind == "one":
            kwargs[f.name] = one(x) if x is not None else (_zero(f.base) if f.base in PRIMS else one({}))
            continue
        if x is None:
            x = [] if f.kind != "array" else [_zero(f.base) if f.base in PRIMS else {} for _ in range(f.n)]
        if not isinstance(x, (list, tuple)):
            raise ValueError(f"{name}.{f.name}: a list expected, got {x!r}")
        if (f.kind == "array" and len(x) != f.n) or (f.kind == "bseq" and len(x) > f.n):
            raise ValueError(f"{name}.{f.name}: {len(x)} items for {f.kind} {f.n}")
        items = [one(v) for v in x]
        kwargs[f.name] = prim_seq(f.base, items) if (prim_seq and f.base in PRIMS) else items
    return make(name, kwargs)


def to_json(msg):
    """A message (any dataclass: Cyclone IDL or rosbags) as JSON-ready dicts, lists and scalars."""
    if dataclasses.is_dataclass(msg):
        # ROS 2 field names start with a lowercase letter; rosbags' classes also hold the constants
        # (uppercase) and "__msgtype__" as dataclass fields, which are left out.
        return {f.name: to_json(getattr(msg, f.name)) for f in dataclasses.fields(msg) if f.name[:1].islower()}
    if isinstance(msg, (bytes, bytearray)):
        return list(msg)
    if isinstance(msg, str):
        return msg
    if hasattr(msg, "tolist"):  # numpy arrays and scalars (rosbags)
        return to_json(msg.tolist())
    if isinstance(msg, (list, tuple)):
        return [to_json(x) for x in msg]
    if isinstance(msg, bool):
        return msg
    if isinstance(msg, int):
        return int(msg)
    if isinstance(msg, float):
        if math.isnan(msg):
            return "NaN"
        if math.isinf(msg):
            return "inf" if msg > 0 else "-inf"
        return msg
    raise ValueError(f"cannot convert {msg!r} to JSON")
