#!/usr/bin/env python3
"""A planner's view of the scene: what stands on the table, then wait for the scene to change.

    PYTHONPATH=build/clients/python python3 clients/python/examples/planner.py --port 7878 --wait 60

Asks scenewatchd for its supporting planes and tracked objects, prints the objects on the table
(the plane most objects stand on), subscribes, and waits for one change event (an object added,
removed or moved, or an appearance change). Then it prints the event and the objects as they are
now. Exit code 0 when a change came, 1 when none came within --wait seconds or on an error.
"""

import argparse
import sys

import scenewatch
from scenewatch import pb


def describe(o):
    c, e = o.centroid, o.box.extents
    return (f"object {o.id}: at ({c.x:.3f}, {c.y:.3f}, {c.z:.3f}) m, "
            f"{e.x * 100:.1f} x {e.y * 100:.1f} x {e.z * 100:.1f} cm, {o.point_count} points")


def objects_on_the_table(client):
    planes = {p.id: p for p in client.get_planes().planes}
    objects = list(client.get_objects().objects)
    if not objects:
        print("no objects yet")
        return
    counts = {}
    for o in objects:
        counts[o.plane_id] = counts.get(o.plane_id, 0) + 1
    table = max(counts, key=counts.get)
    where = f" (height {planes[table].centroid.z:.3f} m)" if table in planes else ""
    print(f"table: plane {table}{where}, {counts[table]} of {len(objects)} objects stand on it")
    for o in objects:
        if o.plane_id == table:
            print("  " + describe(o) + (f", on object {o.supported_by}" if o.supported_by else ""))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=7878)
    parser.add_argument("--timeout", type=float, default=30.0, help="seconds per call")
    parser.add_argument("--wait", type=float, default=60.0, help="seconds to wait for a change (0: forever)")
    args = parser.parse_args()
    try:
        with scenewatch.Client(args.host, args.port, timeout_s=args.timeout) as client, \
                scenewatch.Client(args.host, args.port, timeout_s=args.timeout) as listener:
            # Subscribe first, so that no change between the question and the wait is missed.
            subscription = listener.subscribe(timeout_s=args.wait)
            objects_on_the_table(client)
            print(f"waiting for a change (events after id {subscription.last_event_id})...", flush=True)
            try:
                event = subscription.next()
            except scenewatch.Timeout:
                print(f"no change within {args.wait:g} s")
                return 1
            kind = pb.Event.Kind.Name(event.kind)
            c = event.centroid_world
            target = f" object {event.object_id}" if event.HasField("object_id") else ""
            print(f"event {event.id}: {kind}{target} at ({c.x:.3f}, {c.y:.3f}, {c.z:.3f}) m, "
                  f"score {event.score:.2f}: {event.detail}")
            objects_on_the_table(client)
            return 0
    except scenewatch.Error as e:
        print(f"planner: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
