"""Compression peer for tests/replay_compressed.rs: turns a plain rosbag2 bag written by rosbags
(tests/peers/bag_tool.py) into what `ros2 bag record --compression-format zstd` writes, with the
zstandard bindings of the zstd library rosbag2 links:

- "message": each payload becomes one zstd frame (rosbag2's ZstdCompressor: ZSTD_compress at
  level 1, content size declared); MCAP files are rewritten with the same schemas and channels
  (zstd chunks, as rosbag2's MCAP plugin writes by default), sqlite3 rows updated in place.
- "file": each storage file is compressed whole to `<file>.zstd` and the original removed;
  `relative_file_paths` and `files[].path` name the new files.

Both set `compression_format: zstd` and `compression_mode: MESSAGE` or `FILE` in metadata.yaml.
"rosbags" writes a second copy with rosbags' own Writer and its compression (backports.zstd; in
file mode a streamed frame without a declared size, `compression_mode` in lower case): another
writer of the same format.
Other ops: "encoding" rewrites one MCAP topic's channel message_encoding (a ROS 1 channel);
"format" sets compression_format alone; "read" lists what rosbags' Reader gets from a bag (its
own decompression), to show the compressed bags are the format rosbags knows.

stdin: a JSON request with "op" and "path" (the bag directory).
"""
import hashlib
import json
import re
import sqlite3
import sys
from pathlib import Path

import zstandard

LEVEL = 1  # rosbag2_compression's kDefaultZstdCompressionLevel


def storage_files(bag):
    text = (bag / "metadata.yaml").read_text()
    block = re.search(r"relative_file_paths:\n((?:\s+- .*\n)+)", text)
    return [bag / line.strip()[2:] for line in block.group(1).splitlines()]


def set_field(bag, key, value):
    meta = bag / "metadata.yaml"
    text, n = re.subn(rf"^(\s*{key}:).*$", rf"\g<1> {value}", meta.read_text(), flags=re.M)
    assert n == 1, f"{key} appears {n} times in {meta}"
    meta.write_text(text)


def rewrite_mcap(path, payload=lambda data: data, encoding=lambda channel: channel.message_encoding):
    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        header = reader.get_header()
        messages = [(c.id, m.log_time, m.publish_time, m.sequence, m.data) for _, c, m in reader.iter_messages(log_time_order=False)]
    out = path.with_suffix(".tmp")
    with open(out, "wb") as f:
        w = Writer(f, compression=CompressionType.ZSTD)
        w.start(profile=header.profile, library=header.library)
        schema_ids = {sid: w.register_schema(name=s.name, encoding=s.encoding, data=s.data) for sid, s in summary.schemas.items()}
        channel_ids = {cid: w.register_channel(topic=c.topic, message_encoding=encoding(c), schema_id=schema_ids.get(c.schema_id, 0), metadata=c.metadata)
                       for cid, c in summary.channels.items()}
        for cid, log_time, publish_time, sequence, data in messages:
            w.add_message(channel_id=channel_ids[cid], log_time=log_time, publish_time=publish_time, sequence=sequence, data=payload(data))
        w.finish()
    out.replace(path)
    return len(messages)


def message(req):
    bag = Path(req["path"])
    z = zstandard.ZstdCompressor(level=LEVEL)
    n = 0
    for f in storage_files(bag):
        if f.suffix == ".mcap":
            n += rewrite_mcap(f, payload=z.compress)
        else:
            db = sqlite3.connect(f)
            rows = db.execute("SELECT id, data FROM messages").fetchall()
            db.executemany("UPDATE messages SET data = ? WHERE id = ?", [(z.compress(d), i) for i, d in rows])
            db.commit()
            db.close()
            n += len(rows)
    set_field(bag, "compression_format", "zstd")
    set_field(bag, "compression_mode", "MESSAGE")
    return {"ok": True, "messages": n}


def file(req):
    bag = Path(req["path"])
    z = zstandard.ZstdCompressor(level=LEVEL)
    meta = bag / "metadata.yaml"
    text = meta.read_text()
    names = []
    for f in storage_files(bag):
        Path(f"{f}.zstd").write_bytes(z.compress(f.read_bytes()))
        f.unlink()
        names.append(f.name)
        text, n = re.subn(rf"^(\s*-?\s*(?:path:\s*)?){re.escape(f.name)}$", rf"\g<1>{f.name}.zstd", text, flags=re.M)
        assert n == 2, f"{f.name}: {n} mentions in metadata.yaml (relative_file_paths and files)"
    meta.write_text(text)
    set_field(bag, "compression_format", "zstd")
    set_field(bag, "compression_mode", "FILE")
    return {"ok": True, "files": [f"{n}.zstd" for n in names]}


def encoding(req):
    bag = Path(req["path"])
    for f in storage_files(bag):
        rewrite_mcap(f, encoding=lambda c: req["encoding"] if c.topic == req["topic"] else c.message_encoding)
    return {"ok": True}


def fmt(req):
    set_field(Path(req["path"]), "compression_format", req["format"])
    return {"ok": True}


def rosbags_copy(req):
    from rosbags.rosbag2 import CompressionFormat, CompressionMode, Reader, StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore
    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(req["path"]) as r:
        plugin = StoragePlugin.MCAP if any(Path(req["path"]).glob("*.mcap")) else StoragePlugin.SQLITE3
        w = Writer(req["out"], version=8, storage_plugin=plugin)
        w.set_compression(CompressionMode.FILE if req["mode"] == "file" else CompressionMode.MESSAGE, CompressionFormat.ZSTD)
        with w:
            conns = {c.id: w.add_connection(c.topic, c.msgtype, typestore=store) for c in r.connections}
            for conn, t, raw in r.messages():
                w.write(conns[conn.id], t, bytes(raw))
    return {"ok": True}


def read(req):
    from rosbags.rosbag2 import Reader
    out = []
    with Reader(req["path"]) as r:
        for conn, t, raw in r.messages():
            out.append([conn.topic, t, hashlib.sha256(bytes(raw)).hexdigest()])
    return {"messages": out}


req = json.load(sys.stdin)
json.dump({"message": message, "file": file, "rosbags": rosbags_copy, "encoding": encoding, "format": fmt, "read": read}[req["op"]](req), sys.stdout)
