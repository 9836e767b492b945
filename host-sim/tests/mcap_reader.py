"""Reads a host-sim flight log with the official Python `mcap` reader (PyPI `mcap`), an
independent reader of the file, and prints what it found as one JSON object on stdout.

    python3 mcap_reader.py LOG.mcap

The messages are read linearly (mcap.stream_reader), so that a log whose writer was killed
(no summary, no footer, a chunk cut short) is read up to where it ends; "ended" says how the
reading ended. The summary (indexes, statistics) is read with the seeking reader when the
file has one. "all" holds every message of the channels not at the control rate (the truth,
the navigation sources, the board's, the events). Each message's JSON is parsed and checked against its channel's JSON Schema's
required keys (and each group's members) here, by this reader."""

import json
import sys

from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Attachment, Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader


def check_keys(schema, value, where):
    """The keys the schema requires, no key it does not declare, recursively; the types of
    leaves (one type, or a list of them)."""
    problems = []
    if schema.get("type") == "object":
        if not isinstance(value, dict):
            return [f"{where}: not an object"]
        want = set(schema.get("required", []))
        declared = set(schema.get("properties", {}))
        if not want <= set(value) <= declared:
            problems.append(
                f"{where}: keys {sorted(value)}: required {sorted(want)}, declared {sorted(declared)}"
            )
        for key, sub in schema.get("properties", {}).items():
            if key in value:
                problems += check_keys(sub, value[key], f"{where}.{key}")
        return problems
    types = schema.get("type")
    types = types if isinstance(types, list) else [types]
    python = {
        "number": (int, float),
        "integer": (int,),
        "boolean": (bool,),
        "string": (str,),
        "null": (type(None),),
    }
    ok = any(
        isinstance(value, python[t]) and not (t in ("number", "integer") and isinstance(value, bool))
        for t in types
    )
    if not ok:
        problems.append(f"{where}: {value!r} is not {types}")
    return problems


def main(path):
    schemas, channels, counts, times, problems = {}, {}, {}, {}, []
    attachments, metadata, first, every = {}, {}, {}, {}
    ended = "end of file"
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f, skip_magic=False).records:
                if isinstance(record, Schema):
                    schemas[record.id] = {
                        "name": record.name,
                        "encoding": record.encoding,
                        "schema": json.loads(record.data),
                    }
                elif isinstance(record, Channel):
                    channels[record.id] = {
                        "topic": record.topic,
                        "schema": schemas[record.schema_id]["name"],
                        "encoding": record.message_encoding,
                        "metadata": dict(record.metadata),
                    }
                elif isinstance(record, Message):
                    channel = channels[record.channel_id]
                    topic = channel["topic"]
                    counts[topic] = counts.get(topic, 0) + 1
                    times.setdefault(topic, []).append(record.log_time)
                    value = json.loads(record.data)
                    first.setdefault(topic, value)
                    if topic != "/navigation/told" and not topic.startswith(("/reference", "/control", "/thrusters", "/law")):
                        every.setdefault(topic, []).append(value)
                    schema = next(
                        s["schema"] for s in schemas.values() if s["name"] == channel["schema"]
                    )
                    if len(problems) < 20:
                        problems += check_keys(schema, value, topic)
                    if topic == "/events":
                        first.setdefault("events", []).append(value)
                elif isinstance(record, Attachment):
                    attachments[record.name] = record.data.decode()
                elif isinstance(record, Metadata):
                    metadata[record.name] = dict(record.metadata)
        except (McapError, EOFError, ValueError, Exception) as e:  # noqa: BLE001
            # A log cut short: everything before the cut was read.
            ended = f"{type(e).__name__}: {e}"
    summary = None
    try:
        with open(path, "rb") as f:
            s = make_reader(f).get_summary()
            if s is not None and s.statistics is not None:
                summary = {
                    "message_count": s.statistics.message_count,
                    "chunk_count": s.statistics.chunk_count,
                    # Chunks whose index lists no message: the TypeScript reader (Foxglove)
                    # refuses a file with one ("Chunks without message indexes").
                    "chunks_without_messages": sum(
                        1 for c in s.chunk_indexes if not c.message_index_offsets
                    ),
                    "channel_message_counts": {
                        s.channels[c].topic: n
                        for c, n in s.statistics.channel_message_counts.items()
                    },
                }
    except Exception as e:  # noqa: BLE001
        summary = None
        ended += f"; no summary ({type(e).__name__})"
    out = {
        "schemas": sorted(schemas.values(), key=lambda s: s["name"]),
        "channels": sorted(channels.values(), key=lambda c: c["topic"]),
        "counts": counts,
        "times": times,
        "first": first,
        "all": every,
        "attachments": attachments,
        "metadata": metadata,
        "summary": summary,
        "problems": problems,
        "ended": ended,
    }
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main(sys.argv[1])
