"""The size of each flight log in a folder per minute of flight (docs/logs.md#size).

    python3 scripts/log-sizes.py runs/table1

Reads each `*.mcap` with the official Python `mcap` reader (pip install mcap): its flight time
is the span of its messages' log times (the summary's statistics)."""

import os
import sys

from mcap.reader import make_reader


def main(folder):
    total_bytes, total_minutes = 0, 0.0
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".mcap"):
            continue
        path = os.path.join(folder, name)
        size = os.path.getsize(path)
        with open(path, "rb") as f:
            stats = make_reader(f).get_summary().statistics
        minutes = (stats.message_end_time - stats.message_start_time) / 1e9 / 60
        total_bytes += size
        total_minutes += minutes
        per_minute = size / minutes / 1e6 if minutes > 0 else float("nan")
        print(f"{name}: {size / 1e6:.2f} MB, {minutes:.2f} min of flight, {per_minute:.2f} MB/min")
    if total_minutes > 0:
        print(f"all: {total_bytes / 1e6:.1f} MB for {total_minutes:.1f} min of flight, "
              f"{total_bytes / total_minutes / 1e6:.2f} MB/min")


if __name__ == "__main__":
    main(sys.argv[1])
