#!/usr/bin/env python3
"""Sends a folder to scenewatchd and prints what each frame found.

    PYTHONPATH=build/clients/python python3 clients/python/examples/ingest_folder.py FOLDER [--port 7878]

An RGB-D sequence folder in the 7-Scenes layout (frame-NNNNNN.color.png, .depth.png, .pose.txt,
camera-intrinsics.txt, optional depth-scale.txt) is read here, in pure Python, and sent frame by
frame with IngestFrame. Any other folder: its .pcd and .ply files are ingested by the daemon
itself with IngestFile (the folder must lie under the daemon's server.data_roots).
Exit code 0 when every frame was accepted, 1 otherwise.
"""

import argparse
import os
import sys

import scenewatch
from scenewatch import pb
from scenewatch.rgbd import Sequence


def report(name, reply):
    kinds = ", ".join(pb.Event.Kind.Name(e.kind) for e in reply.events)
    print(f"{name}: {reply.points} points, {len(reply.planes)} planes, {len(reply.clusters)} objects, "
          f"{len(reply.events)} event{'' if len(reply.events) == 1 else 's'}{' (' + kinds + ')' if kinds else ''}, "
          f"{reply.total_ms:.0f} ms", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=7878)
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds per call")
    parser.add_argument("--depth-scale", type=float, help="metres per depth unit (default: depth-scale.txt, or mm)")
    parser.add_argument("--token-file", help="the daemon's access token file (default ~/.scenewatch/token)")
    args = parser.parse_args()
    failures = 0
    try:
        with scenewatch.Client(args.host, args.port, timeout_s=args.timeout, token_file=args.token_file) as client:
            if any(name.endswith(".color.png") for name in os.listdir(args.folder)):
                sequence = Sequence(args.folder, depth_scale_m=args.depth_scale)
                for i in range(len(sequence)):
                    try:
                        report(sequence.names[i], client.ingest_frame(sequence.frame(i)))
                    except (scenewatch.StatusError, ValueError) as e:
                        print(f"{sequence.names[i]}: {e}", file=sys.stderr)
                        failures += 1
            else:
                files = sorted(f for f in os.listdir(args.folder) if f.endswith((".pcd", ".ply")))
                if not files:
                    print(f"{args.folder}: no frame-NNNNNN.color.png, .pcd or .ply files", file=sys.stderr)
                    return 1
                for name in files:
                    try:
                        report(name, client.ingest_file(os.path.abspath(os.path.join(args.folder, name))))
                    except scenewatch.StatusError as e:
                        print(f"{name}: {e}", file=sys.stderr)
                        failures += 1
    except (scenewatch.Error, OSError, ValueError) as e:
        print(f"ingest_folder: {e}", file=sys.stderr)
        return 1
    return 0 if failures == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
