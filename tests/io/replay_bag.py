#!/usr/bin/python3
"""`scenewatch replay --json --objects` on ROS bags gives the same events, objects and summary as
on the same frames read from the folder (usage: replay_bag.py SCENEWATCH DATA_DIR [--cdr-tool CYCLONE_CDR]).

The bags are written by tests/io/make_bag.py from the folders' first frames: ROS 1 bags by
Debian's python3-rosbag (lz4 chunks), a rosbag2 SQLite bag and an MCAP file with zstd chunks
(containers from their specifications and CDR by hand: ours). With --cdr-tool, only the rosbag2 and
MCAP bags are written, every message serialized by Cyclone DDS (tests/ros/cyclone_cdr). Only the
fields that cannot agree are left out: each line's "source" (a file path or BAG:N), an event's
stamp_s and the timings. The folder read is a copy of the frames whose poses are made exactly rigid (7-Scenes'
rotations are orthonormal to 1e-5; TF's quaternions cannot carry that). Numbers must agree to
1e-6 (the poses went through a quaternion and a TF chain)."""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
# Timings, each line's source, and the event's stamp (a frames-layout folder has no time, it counts
# frames at 30 per second; the bag's stamps are the recording's).
TIMINGS = {"median_frame_ms", "p90_frame_ms", "median_stage_ms", "median_ms", "source", "stamp_s"}


def strip(value):
    if isinstance(value, dict):
        return {k: strip(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [strip(v) for v in value]
    return value


def same(a, b, path="$"):
    if isinstance(a, float) or isinstance(b, float):
        if not isinstance(a, (int, float)) or not isinstance(b, (int, float)) or abs(a - b) > 1e-6 * max(1.0, abs(a), abs(b)):
            return "%s: %r vs %r" % (path, a, b)
        return None
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return "%s: keys %s vs %s" % (path, sorted(a), sorted(b))
        for k in a:
            d = same(a[k], b[k], path + "." + k)
            if d:
                return d
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return "%s: %d vs %d items" % (path, len(a), len(b))
        for i, (x, y) in enumerate(zip(a, b)):
            d = same(x, y, "%s[%d]" % (path, i))
            if d:
                return d
        return None
    return None if a == b else "%s: %r vs %r" % (path, a, b)


def replay(scenewatch, spec):
    out = subprocess.run([scenewatch, "replay", "--json", "--objects", spec], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit("scenewatch replay %s failed (%d): %s" % (spec, out.returncode, out.stderr))
    return [strip(json.loads(line)) for line in out.stdout.splitlines() if line.strip()]


# (folder under the data dir, frames, bags): the kitchen (a static room: objects and planes per
# frame, no event) and hrt1's pick_toy_1 (a hand takes a toy: an event).
CASES = [
    ("redkitchen_long", 10, [("kitchen.bag", ["--format", "ros1", "--compression", "lz4"]),
                             ("kitchen_rosbag2", ["--format", "rosbag2"]),
                             ("kitchen.mcap", ["--format", "mcap", "--compression", "zstd"])]),
    ("hrt1/pick_toy_1", 40, [("pick_toy_1.bag", ["--format", "ros1", "--compression", "bz2"]),
                             ("pick_toy_1.mcap", ["--format", "mcap", "--compression", "lz4"])]),
]


def main():
    scenewatch, data = sys.argv[1], sys.argv[2]
    cdr_tool = sys.argv[4] if len(sys.argv) == 5 and sys.argv[3] == "--cdr-tool" else None
    cases = CASES
    if cdr_tool:
        cases = [(sub, frames, [(name, args + ["--cdr-tool", cdr_tool]) for name, args in bags if "ros1" not in args])
                 for sub, frames, bags in CASES]
        cases[1][2].append(("pick_toy_1_rosbag2", ["--format", "rosbag2", "--cdr-tool", cdr_tool]))
    if not os.path.isdir(data):
        print("real data not found: %s" % data)
        return 77
    failures = 0
    for sub, frames, bags in cases:
        folder = os.path.join(data, sub)
        with tempfile.TemporaryDirectory(prefix="scenewatch-replay-bag-") as tmp:
            # The folder's frames with their poses made exactly rigid, as TF carries them.
            oracle = os.path.join(tmp, "oracle")
            subprocess.run(["/usr/bin/python3", os.path.join(HERE, "make_bag.py"), folder, os.path.join(tmp, "unused.bag"),
                            "--count", str(frames), "--oracle", oracle], check=True)
            expected = replay(scenewatch, oracle)
            summary = expected[-1]
            print("%s: folder: %d lines, %d frames, %d events" % (sub, len(expected), summary["frames"], summary["events"]))
            assert summary["frames"] == frames, summary
            for name, args in bags:
                bag = os.path.join(tmp, name)
                subprocess.run(["/usr/bin/python3", os.path.join(HERE, "make_bag.py"), folder, bag, "--count", str(frames)] + args,
                               check=True)
                got = replay(scenewatch, bag)
                diff = same(expected, got)
                print("  %s: %d lines; %s" % (name, len(got), "same as the folder" if diff is None else "DIFFERS at " + diff))
                failures += diff is not None
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
