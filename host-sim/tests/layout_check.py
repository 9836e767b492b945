"""Checks the shipped layouts (layouts/*.foxglove.json, layouts/*.plotjuggler.xml) against a
real flight log, independently of host-sim: the layouts are parsed here (json,
xml.etree), the log with the official Python `mcap` reader, and every series a layout names
is looked up in the log's channels and JSON Schemas, and counted in its messages.

    python3 layout_check.py LAYOUT_DIR LOG.mcap

Prints one JSON object: for each layout, every series it names (as the layout writes it),
the channel and field it resolves to (a Foxglove message path `/topic.field.member`, a
PlotJuggler series `/topic/field/member`: the longest channel topic that prefixes it), the
schema's type at that field (null when the schema has no such field), and how many messages
have a value there (a number, a boolean, or a text for a Foxglove state panel)."""

import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from mcap.reader import make_reader


def read_log(path):
    """Channels: topic -> (schema, [decoded messages])."""
    channels = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            entry = channels.setdefault(channel.topic, (json.loads(schema.data), []))
            entry[1].append(json.loads(message.data))
    # Channels with no message are declared in the summary.
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
        for channel in summary.channels.values():
            if channel.topic not in channels:
                schema = summary.schemas[channel.schema_id]
                channels[channel.topic] = (json.loads(schema.data), [])
    return channels


def resolve(ref, channels, sep):
    """(topic, [field names]) of a layout's series, or (None, None)."""
    best = None
    for topic in channels:
        if ref.startswith(topic + sep) and (best is None or len(topic) > len(best)):
            best = topic
    if best is None:
        return None, None
    return best, ref[len(best) + 1 :].split(sep)


def schema_type(schema, fields):
    for name in fields:
        props = schema.get("properties", {})
        if name not in props:
            return None
        schema = props[name]
    t = schema.get("type")
    return t if isinstance(t, list) else [t]


def count(messages, fields):
    n = 0
    for m in messages:
        for name in fields:
            m = m.get(name) if isinstance(m, dict) else None
        if isinstance(m, (int, float, bool, str)):
            n += 1
    return n


def foxglove_refs(doc):
    refs = []
    for panel_id, config in doc["configById"].items():
        kind = panel_id.split("!")[0]
        for p in config.get("paths", []):
            refs.append((p["value"], kind))
        if config.get("xAxisVal") == "custom":
            refs.append((config["xAxisPath"]["value"], kind))
    return refs


def plotjuggler_refs(root):
    refs = []
    for curve in root.iter("curve"):
        if curve.get("curve_x"):
            refs += [(curve.get("curve_x"), "XYPlot"), (curve.get("curve_y"), "XYPlot")]
        else:
            refs.append((curve.get("name"), "TimeSeries"))
    return refs


def check(refs, channels, sep):
    out = []
    for ref, panel in refs:
        topic, fields = resolve(ref, channels, sep)
        entry = {"ref": ref, "panel": panel, "topic": topic, "field": None, "type": None, "messages": 0}
        if topic is not None:
            schema, messages = channels[topic]
            entry["field"] = ".".join(fields)
            entry["type"] = schema_type(schema, fields)
            entry["messages"] = count(messages, fields)
        out.append(entry)
    return out


def main(layouts, log):
    channels = read_log(log)
    found = {"topics": sorted(channels), "layouts": {}}
    for path in sorted(Path(layouts).iterdir()):
        if path.name.endswith(".foxglove.json"):
            refs = foxglove_refs(json.loads(path.read_text()))
            found["layouts"][path.name] = check(refs, channels, ".")
        elif path.name.endswith(".plotjuggler.xml"):
            refs = plotjuggler_refs(ET.parse(path).getroot())
            found["layouts"][path.name] = check(refs, channels, "/")
    json.dump(found, sys.stdout)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
