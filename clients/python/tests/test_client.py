"""The Python client against the real scenewatchd on a loopback port: every call, the errors,
timeouts, and a subscription that hears the change an ingest causes."""

import json
import math
import os
import shutil
import socket
import struct
import tempfile
import unittest

import scenewatch
from scenewatch import pb
from scenewatch.rgbd import Sequence, read_numbers, read_png

from daemon import SOURCE_DIR, Daemon, render

SAMPLE_DIR = os.path.join(SOURCE_DIR, "sample_clouds")
TABLETOP_PCD = os.path.join(SAMPLE_DIR, "tabletop.pcd")  # frame 0 of tabletop/, in its camera frame


def tabletop_pose():
    """The camera pose of the sample frame (the PCD is in the camera frame; z is up in the world)."""
    m = read_numbers(os.path.join(SAMPLE_DIR, "tabletop", "frame-000000.pose.txt"))
    return [m[0:4], m[4:8], m[8:12], m[12:16]]
UP = "segmentation:\n  up_vector: [0, 0, 1]\n"


class Rendered:
    """cup_added at 320x240, 12 frames per phase, rendered once for the whole module."""
    dir = None

    @classmethod
    def get(cls):
        if cls.dir is None:
            cls.dir = tempfile.mkdtemp(prefix="scenewatch-py-cup-")
            render("cup_added", cls.dir, frames=12)
        return cls.dir


def tearDownModule():
    if Rendered.dir:
        shutil.rmtree(Rendered.dir, ignore_errors=True)


class ClientTest(unittest.TestCase):
    def setUp(self):
        self.daemon = Daemon(UP, data_roots=[SAMPLE_DIR])
        self.addCleanup(self.daemon.cleanup)
        self.client = scenewatch.Client("127.0.0.1", self.daemon.port, timeout_s=60, token_file=self.daemon.token_file)
        self.addCleanup(self.client.close)

    def test_every_call_on_the_sample_tabletop(self):
        health = self.client.health()
        self.assertIsInstance(health, pb.HealthReply)
        self.assertTrue(health.version)
        self.assertEqual(health.frames_processed, 0)

        # IngestFile: the simulator's tabletop (a box, a bottle, a mug, a can on a table).
        reply = self.client.ingest_file(TABLETOP_PCD, pose=tabletop_pose(), stamp_s=1.0)
        self.assertIsInstance(reply, pb.IngestReply)
        self.assertGreater(reply.points, 50000)
        self.assertEqual(len(reply.clusters), 4)
        self.assertEqual(reply.localization.state, "given", "the daemon's default: poses as they come")
        for used, given in zip(reply.localization.pose.matrix, [x for row in tabletop_pose() for x in row]):
            self.assertAlmostEqual(used, given, places=6)
        with self.assertRaisesRegex(ValueError, "given, refine or track"):
            self.client.ingest_frame(localization="fly")

        stats = self.client.stats()
        self.assertEqual(stats.frames_processed, 1)
        self.assertEqual(stats.points_processed, reply.points)
        self.assertGreater(stats.map_occupied_leaves, 0)
        self.assertEqual(stats.connections, 1)

        # GetLocalization: the default camera sent the frame; its poses are taken as given.
        where = self.client.get_localization()
        self.assertEqual([c.camera for c in where.cameras], [""])
        self.assertEqual(where.cameras[0].state, "given")
        self.assertEqual(len(where.cameras[0].T_world_odom.matrix), 16)
        self.assertEqual(self.client.get_localization("").cameras[0].state, "given")
        with self.assertRaisesRegex(scenewatch.StatusError, "NOT_FOUND.*camera 'nope'"):
            self.client.get_localization("nope")

        planes = self.client.get_planes()
        self.assertEqual(planes.frames_processed, 1)
        self.assertGreaterEqual(len(planes.planes), 1)
        objects = self.client.get_objects().objects
        self.assertEqual(len(objects), 4)
        self.assertEqual(len({o.plane_id for o in objects}), 1, "all four stand on one plane")
        table = next(p for p in planes.planes if p.id == objects[0].plane_id)
        self.assertAlmostEqual(table.centroid.z, 0.75, delta=0.01, msg="the table top, 75 cm high")
        self.assertFalse(objects[0].HasField("ontology"), "described only on request")

        # Described by the ontology: the scene's mug (r 42 mm), can (r 33 mm) and box have their
        # classes; the 26 cm bottle is taller than any class allows.
        described = self.client.get_objects(describe=True).objects
        classes = sorted(o.ontology.class_name for o in described)
        self.assertEqual(classes, ["box", "can", "cup", "unknown"])
        can = next(o for o in described if o.ontology.class_name == "can")
        self.assertAlmostEqual(can.ontology.primitive.radius_m, 0.033, delta=0.002)
        cup = next(o for o in described if o.ontology.class_name == "cup")
        self.assertGreaterEqual(len(cup.ontology.grasps), 1)

        # No hand in this frame; no object was handled.
        hands = self.client.get_hands()
        self.assertIsInstance(hands, pb.HandsReply)
        self.assertEqual(len(hands.hands), 0)
        self.assertFalse(any(o.foreground for o in described))

        # Occupancy: on the table top, in the air above it, under the table (never seen).
        top = objects[0]
        occupancy = self.client.query_occupancy(points=[(0.3, -0.25, 0.75), (0, 0, 1), (0, 0, 0.3)],
                                                box=((-0.05, -0.05, 0.7), (0.05, 0.05, 0.8)))
        self.assertEqual(list(occupancy.states), [pb.OCCUPANCY_OCCUPIED, pb.OCCUPANCY_FREE, pb.OCCUPANCY_UNKNOWN])
        self.assertTrue(occupancy.HasField("box"))
        self.assertGreater(occupancy.box.occupied_voxels + occupancy.box.free_voxels, 0)

        # NextBestView: seen from one camera, the object's back is unknown; the best view reaches
        # some of it, so its expected coverage is above the coverage now.
        nbv = self.client.next_best_view(object_id=top.id, n=3)
        self.assertIsInstance(nbv, pb.NextBestViewReply)
        self.assertEqual(len(nbv.views), 3)
        self.assertEqual(len(nbv.views[0].pose.matrix), 16)
        self.assertGreaterEqual(nbv.views[0].score, nbv.views[1].score)
        self.assertGreater(nbv.views[0].expected_coverage, nbv.coverage)
        self.assertTrue(nbv.target_description.startswith(("the completed surface of a", "the object's box")),
                        nbv.target_description)
        with self.assertRaises(ValueError):
            self.client.next_best_view(object_id=top.id, workspace=True)

        # ClearBox around the first object frees its voxels.
        e = top.box.extents
        lo = (top.centroid.x - e.x, top.centroid.y - e.y, top.centroid.z - e.z)
        hi = (top.centroid.x + e.x, top.centroid.y + e.y, top.centroid.z + e.z)
        self.assertGreater(self.client.clear_box(lo, hi).voxels_changed, 0)

        self.assertEqual(self.client.get_events(since=0), [], "one frame raises no event")
        saved = self.client.save_model()
        self.assertEqual(os.path.realpath(saved.model_dir), os.path.realpath(self.daemon.model_dir))
        self.client.reset()
        self.assertEqual(len(self.client.get_objects().objects), 0)
        loaded = self.client.load_model()
        self.assertEqual(loaded.objects, 4)
        self.assertEqual(len(self.client.get_objects().objects), 4)

    def test_a_subscriber_hears_the_cup_that_was_added(self):
        rendered = Rendered.get()
        with open(os.path.join(rendered, "changes.json")) as f:
            truth = json.load(f)["transitions"][0]["added"][0]["T_world_object"]
        cup_xy = (truth[0][3], truth[1][3])

        listener = scenewatch.Client("127.0.0.1", self.daemon.port, timeout_s=60)
        self.addCleanup(listener.close)
        subscription = listener.subscribe(timeout_s=60)
        self.assertEqual(subscription.last_event_id, 0)
        replied = []
        pending_at_cup = None  # the cup while it is seen but not yet confirmed
        for phase in ("before", "after"):
            sequence = Sequence(os.path.join(rendered, phase))
            self.assertEqual(len(sequence), 12)
            for i in range(len(sequence)):
                reply = self.client.ingest_frame(sequence.frame(i, stamp_s=len(replied) / 30.0))
                replied.append(reply)
                for c in self.client.get_pending_changes().changes:
                    near = math.hypot(c.centroid_world.x - cup_xy[0], c.centroid_world.y - cup_xy[1]) < 0.10
                    if pending_at_cup is None and c.kind == pb.PendingChange.ADDED and near:
                        pending_at_cup = c
                        views = self.client.next_best_view(pending_id=c.id)
                        self.assertEqual(views.measure, "visible")
                        self.assertGreater(views.views[0].score, 0)
        self.assertIsNotNone(pending_at_cup, "the cup was pending before it was confirmed")
        self.assertEqual(pending_at_cup.hits_needed, 3)
        events = [e for r in replied for e in r.events]
        self.assertEqual([pb.Event.Kind.Name(e.kind) for e in events], ["OBJECT_ADDED"])
        self.assertTrue(all(len(r.events) == 0 for r in replied[:12]), "nothing changed before the cup")

        event = next(iter(subscription))
        self.assertEqual(event.kind, pb.Event.OBJECT_ADDED)
        self.assertEqual(event.id, events[0].id)
        self.assertLess(math.hypot(event.centroid_world.x - cup_xy[0], event.centroid_world.y - cup_xy[1]), 0.10)
        with self.assertRaises(scenewatch.Timeout):
            subscription.next(timeout_s=0.5)  # one fact, one event
        self.assertEqual([e.id for e in self.client.get_events(since=0)], [event.id])
        self.assertIn(pending_at_cup.id, event.pending_ids)
        with self.assertRaises(scenewatch.StatusError) as caught:
            self.client.next_best_view(pending_id=pending_at_cup.id)
        self.assertEqual(caught.exception.code, pb.Status.NOT_FOUND)
        self.assertIn("confirmed as event %d" % event.id, caught.exception.message)

        # The surprise map of the last posed frame: one float per pixel of the 320x240 frames.
        surprise = self.client.get_surprise_map(include_channels=True)
        self.assertEqual((surprise.width, surprise.height), (320, 240))
        self.assertEqual(len(surprise.total), 4 * 320 * 240)
        self.assertEqual(len(surprise.channels), 3)
        self.assertGreater(surprise.known_pixels, 320 * 240 // 4)
        self.assertGreaterEqual(surprise.reference_views, 1)

    def test_a_subscriber_is_told_when_a_camera_is_lost_and_found(self):
        rendered = Rendered.get()
        listener = scenewatch.Client("127.0.0.1", self.daemon.port, timeout_s=60)
        self.addCleanup(listener.close)
        subscription = listener.subscribe(timeout_s=60)
        sequence = Sequence(os.path.join(rendered, "before"))
        seen = []  # (state, homed) as each ingest reply says
        for i in range(6):
            frame = sequence.frame(i)
            frame.camera = "arm"
            frame.localization = pb.LOCALIZATION_REFINE
            if i == 3:
                frame.pose.matrix[3] += 1.0  # 1 m off along x: the alignment cannot accept it
            reply = self.client.ingest_frame(frame)
            seen.append((reply.localization.state, reply.localization.homed))
        self.assertEqual(seen[3][0], "lost")
        self.assertEqual(seen[-1][0], "tracking")
        changes = [s for k, s in enumerate(seen) if k == 0 or seen[k - 1] != s]
        listener.stats()  # a call: what was pushed before its reply is collected meanwhile
        notices = list(subscription.localization_changes)
        self.assertEqual([(c.state, c.homed) for c in notices], changes)
        self.assertEqual({c.camera for c in notices}, {"arm"})
        self.assertTrue(notices[changes.index(seen[3])].reason, "a lost camera says why")
        with self.assertRaises(scenewatch.Timeout):
            subscription.next(timeout_s=0.5)  # notices are not events

    def test_pure_python_frames_match_the_files(self):
        # The back-projection of rgbd.py against the organized PCD the simulator wrote of the same
        # frame (sample_clouds/tabletop.pcd is frame 0 of sample_clouds/tabletop/).
        sequence = Sequence(os.path.join(SAMPLE_DIR, "tabletop"))
        frame = sequence.frame(0)
        self.assertEqual((frame.cloud.width, frame.cloud.height), (320, 240))
        xyz = struct.unpack(f"<{3 * 320 * 240}f", frame.cloud.xyz)
        valid = sum(1 for i in range(0, len(xyz), 3) if not math.isnan(xyz[i + 2]))
        by_file = self.client.ingest_file(TABLETOP_PCD, pose=tabletop_pose())
        by_frame = self.client.ingest_frame(frame)
        self.assertEqual(valid, by_file.points)
        self.assertEqual(by_frame.points, by_file.points)
        self.assertEqual(len(by_frame.clusters), len(by_file.clusters))
        depth = read_png(os.path.join(SAMPLE_DIR, "tabletop", "frame-000000.depth.png"))
        self.assertEqual((depth.width, depth.height, depth.channels, depth.bit_depth), (320, 240, 1, 16))

    def test_images_sent_as_they_are_give_what_the_cloud_gives(self):
        # The same frame as IngestFrame.rgbd: the daemon back-projects it into the same points.
        cloud = Sequence(os.path.join(SAMPLE_DIR, "tabletop")).frame(0)
        images = Sequence(os.path.join(SAMPLE_DIR, "tabletop"), send_images=True).frame(0)
        self.assertTrue(images.HasField("rgbd") and not images.HasField("cloud"))
        self.assertEqual(len(images.rgbd.depth_mm), 2 * 320 * 240)
        self.assertLess(images.ByteSize(), cloud.ByteSize() / 2.5)
        by_cloud = self.client.ingest_frame(cloud)
        by_images = self.client.ingest_frame(images)
        self.assertEqual(by_images.points, by_cloud.points)
        self.assertEqual(len(by_images.clusters), len(by_cloud.clusters))
        self.assertEqual(len(by_images.planes), len(by_cloud.planes))
        # Without intrinsics the daemon cannot back-project: refused, naming them.
        images.ClearField("intrinsics")
        with self.assertRaises(scenewatch.StatusError) as caught:
            self.client.ingest_frame(images)
        self.assertIn("intrinsics", caught.exception.message)

    def test_a_refused_request_raises_the_daemons_status(self):
        # A cloud whose byte count disagrees with its size.
        bad = pb.IngestFrame(cloud=pb.Cloud(width=10, height=1, xyz=b"\0" * 12))
        with self.assertRaises(scenewatch.StatusError) as caught:
            self.client.ingest_frame(bad)
        self.assertEqual(caught.exception.code, pb.Status.INVALID_ARGUMENT)
        self.assertEqual(caught.exception.code_name, "INVALID_ARGUMENT")
        self.assertIn("xyz", caught.exception.message)
        self.assertIn("INVALID_ARGUMENT", str(caught.exception))

        with self.assertRaises(scenewatch.StatusError) as caught:
            self.client.ingest_file("/etc/hostname")
        self.assertEqual(caught.exception.code, pb.Status.PERMISSION_DENIED)

        with self.assertRaises(scenewatch.StatusError) as caught:
            self.client.get_surprise_map()
        self.assertEqual(caught.exception.code, pb.Status.NOT_FOUND)

        # Without the daemon's token, calls that change the model are refused; reading is open.
        with scenewatch.Client("127.0.0.1", self.daemon.port, timeout_s=60, token="") as stranger:
            self.assertEqual(stranger.token, "")
            with self.assertRaises(scenewatch.StatusError) as caught:
                stranger.reset()
            self.assertEqual(caught.exception.code, pb.Status.PERMISSION_DENIED)
            self.assertIn("token", caught.exception.message)
            self.assertIsInstance(stranger.stats(), pb.StatsReply)
            with self.assertRaises(scenewatch.StatusError) as caught:
                stranger.define_class("classes: []")
            self.assertEqual(caught.exception.code, pb.Status.PERMISSION_DENIED)
            self.assertIn("cup", [c.name for c in stranger.list_classes().classes])

        # Object classes: a bad one names its field; a good one is listed.
        with self.assertRaises(scenewatch.StatusError) as caught:
            self.client.define_class("classes:\n  - {name: pot, shape: cylinder, radius_m: [0.2, 0.1], height_m: [0.1, 0.2]}\n")
        self.assertIn("radius_m", caught.exception.message)
        reply = self.client.define_class("classes:\n  - {name: pot, shape: cylinder, radius_m: [0.1, 0.2], height_m: [0.1, 0.2]}\n")
        self.assertEqual(list(reply.defined), ["pot"])
        self.assertIn("pot", [c.name for c in self.client.list_classes().classes])

        with self.assertRaises(ValueError):
            self.client.ingest_frame(cloud=bad.cloud, pose=[1, 0, 0])
        with self.assertRaises(TypeError):
            self.client.ingest_frame(bad, stamp_s=1.0)
        # The connection survives refusals, and nothing changed.
        self.assertEqual(self.client.stats().frames_processed, 0)

    def test_timeouts_and_late_answers(self):
        # A frame takes far longer than a millisecond: the call times out, the connection stays
        # usable and the late ingest reply is skipped, not taken for the next call's answer.
        self.client.timeout_s = 0.001
        with self.assertRaises(scenewatch.Timeout):
            self.client.ingest_file(TABLETOP_PCD, pose=tabletop_pose())
        self.client.timeout_s = 60
        self.assertIsInstance(self.client.health(), pb.HealthReply)
        self.assertEqual(self.client.stats().frames_processed, 1)

        # A listener that never answers.
        silent = socket.socket()
        silent.bind(("127.0.0.1", 0))
        silent.listen(1)
        self.addCleanup(silent.close)
        with scenewatch.Client("127.0.0.1", silent.getsockname()[1], timeout_s=0.2) as mute:
            with self.assertRaises(scenewatch.Timeout):
                mute.health()

    def test_connection_errors(self):
        free = socket.socket()
        free.bind(("127.0.0.1", 0))
        port = free.getsockname()[1]
        free.close()
        with self.assertRaises(scenewatch.ConnectionLost) as caught:
            scenewatch.Client("127.0.0.1", port, timeout_s=5)
        self.assertIn(f"127.0.0.1:{port}", str(caught.exception))

        listener = scenewatch.Client("127.0.0.1", self.daemon.port, timeout_s=5)
        self.addCleanup(listener.close)
        subscription = iter(listener.subscribe(timeout_s=30))
        self.assertEqual(self.daemon.stop(), 0)
        with self.assertRaises(scenewatch.ConnectionLost):
            self.client.health()
        with self.assertRaises(scenewatch.ConnectionLost):
            next(subscription)  # a subscriber is told, not left waiting


if __name__ == "__main__":
    unittest.main()
