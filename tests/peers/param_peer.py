"""The node's parameter services called as `ros2 param` on rmw_cyclonedds_cpp calls them: Cyclone
DDS from Python, Cyclone's request/reply mapping (a (guid, seq) header before the .srv's fields,
the reply matched by both), for tests/fastdds_interop.rs (the node with service_mapping:=cyclone).
Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).

stdin: {"domain": id, "node": "name", "calls": [{"service": "get_parameters"|"get_parameter_types"|
        "set_parameters"|"set_parameters_atomically"|"list_parameters"|"describe_parameters",
        "request": {...}}], "timeout": s}
        get/get types/describe: {"names": [...]}; set: P = {"name": n, "double": x} or {"name": n,
        "string": s}; set atomically: {"parameters": [P...]}; list: {"prefixes": [...], "depth": n}
stdout: {"answers": [A or null ...]}; A: get {"values": [[type, double, string]...]}, get types
        {"types"}, set {"results": [[successful, reason]]}, set atomically {"result": [successful,
        reason]}, list {"names", "prefixes"}, describe {"types", "read_only"}
"""
import json
import sys
import time
from pathlib import Path

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

sys.path.insert(0, str(Path(__file__).resolve().parent))
import dds_types as d  # noqa: E402

GUID = 0x1122334455667788


def with_header(cls):
    """Cyclone's form of a service type: (guid, seq) before the fields, the same DDS name."""
    pkg, kind, _dds, name = cls.__idl_typename__.split("::")
    return d.struct_typed(f"{pkg}/{kind}/{name[:-1]}", [("guid", d.t.uint64), ("seq", d.t.int64)] + list(cls.__annotations__.items()))


SERVICES = {"get_parameters": (d.GetReq, d.GetResp), "set_parameters": (d.SetReq, d.SetResp),
            "list_parameters": (d.ListReq, d.ListResp), "describe_parameters": (d.DescribeReq, d.DescribeResp),
            "get_parameter_types": (d.GetTypesReq, d.GetTypesResp), "set_parameters_atomically": (d.SetAtomicReq, d.SetAtomicResp)}


def pv(c):
    double, string = c.get("double"), c.get("string")
    return d.ParameterValue(type=3 if double is not None else 4, bool_value=False, integer_value=0, double_value=float(double or 0.0),
                            string_value=string or "", byte_array_value=[], bool_array_value=[], integer_array_value=[],
                            double_array_value=[], string_array_value=[])


def body(service, r):
    if service in ("get_parameters", "describe_parameters", "get_parameter_types"):
        return {"names": r["names"]}
    if service == "set_parameters":
        return {"parameters": [d.Parameter(name=r["name"], value=pv(r))]}
    if service == "set_parameters_atomically":
        return {"parameters": [d.Parameter(name=x["name"], value=pv(x)) for x in r["parameters"]]}
    return {"prefixes": r.get("prefixes", []), "depth": int(r.get("depth", 0))}


def show(service, x):
    if service == "get_parameters":
        return {"values": [[int(v.type), v.double_value, v.string_value] for v in x.values]}
    if service == "set_parameters":
        return {"results": [[bool(v.successful), v.reason] for v in x.results]}
    if service == "list_parameters":
        return {"names": list(x.result.names), "prefixes": list(x.result.prefixes)}
    if service == "get_parameter_types":
        return {"types": [int(v) for v in x.types]}
    if service == "set_parameters_atomically":
        return {"result": [bool(x.result.successful), x.result.reason]}
    return {"types": [int(v.type) for v in x.descriptors], "read_only": [bool(v.read_only) for v in x.descriptors]}


req = json.load(sys.stdin)
dp = DomainParticipant(req["domain"])
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10))
out = {"answers": []}
seq = 0
for c in req["calls"]:
    service = c["service"]
    q_type, r_type = (with_header(x) for x in SERVICES[service])
    w = DataWriter(dp, Topic(dp, f"rq/{req['node']}/{service}Request", q_type), qos=reliable)
    r = DataReader(dp, Topic(dp, f"rr/{req['node']}/{service}Reply", r_type), qos=reliable)
    end = time.time() + req.get("timeout", 20)
    while (w.get_matched_subscriptions() == [] or r.get_matched_publications() == []) and time.time() < end:
        time.sleep(0.05)
    time.sleep(0.2)
    answer, sent = None, set()
    # A request written before the node has matched our reader gets a reply we never see: resend
    # (a fresh sequence number) after each second without the answer.
    while answer is None and time.time() < end:
        seq += 1
        sent.add(seq)
        w.write(q_type(guid=GUID, seq=seq, **body(service, c["request"])))
        resend = time.time() + 1.0
        while answer is None and time.time() < min(resend, end):
            for x in r.take(N=10):
                if x.guid == GUID and x.seq in sent:
                    answer = show(service, x)
            time.sleep(0.01)
    out["answers"].append(answer)
json.dump(out, sys.stdout)
