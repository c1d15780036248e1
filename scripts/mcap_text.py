"""An MCAP file as text, for scripts/cli_outputs.sh: every record a reader sees (header, schemas,
channels, statistics, chunk indexes, metadata, attachments) and every message in file order with
its times, sequence, size and fields decoded from the file's own schemas (mcap-ros2-support).

Chunks' compressed sizes are left out: a timing field inside a message (CollisionReport's
check_seconds) changes them from run to run, and the script masks that field in this text.

usage: $TC_PYTHON scripts/mcap_text.py FILE.mcap > FILE.mcap.txt
"""
import hashlib
import sys

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

with open(sys.argv[1], "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    h = reader.get_header()
    print(f"header profile={h.profile!r} library={h.library!r}")
    s = reader.get_summary()
    for sid, sc in sorted(s.schemas.items()):
        print(f"schema {sid} {sc.name} {sc.encoding} sha1={hashlib.sha1(sc.data).hexdigest()}")
    for cid, c in sorted(s.channels.items()):
        print(f"channel {cid} {c.topic} schema={c.schema_id} {c.message_encoding} {sorted(c.metadata.items())}")
    st = s.statistics
    print(f"statistics messages={st.message_count} schemas={st.schema_count} channels={st.channel_count} chunks={st.chunk_count} "
          f"attachments={st.attachment_count} metadata={st.metadata_count} start={st.message_start_time} end={st.message_end_time} "
          f"per_channel={sorted(st.channel_message_counts.items())}")
    for ci in s.chunk_indexes:
        print(f"chunk start={ci.message_start_time} end={ci.message_end_time} compression={ci.compression!r} uncompressed={ci.uncompressed_size}")
    for m in reader.iter_metadata():
        print(f"metadata {m.name} {sorted(m.metadata.items())}")
    for a in reader.iter_attachments():
        print(f"attachment {a.name} {a.media_type} sha1={hashlib.sha1(a.data).hexdigest()}")
    for _, channel, message, decoded in reader.iter_decoded_messages(log_time_order=False):
        print(f"message {channel.topic} log={message.log_time} publish={message.publish_time} seq={message.sequence} bytes={len(message.data)} {decoded!r}")
