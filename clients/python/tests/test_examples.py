"""The two examples, run as a user runs them, against the real scenewatchd."""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import math
import unittest

from daemon import EXAMPLES_DIR, SOURCE_DIR, Daemon, render

UP = "segmentation:\n  up_vector: [0, 0, 1]\n"
CUP_XY = (-0.15, -0.08)  # where cup_added.yaml puts the cup


def example(name, *args, **kwargs):
    return subprocess.run([sys.executable, os.path.join(EXAMPLES_DIR, name), *map(str, args)],
                          capture_output=True, text=True, timeout=300, **kwargs)


class ExamplesTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="scenewatch-py-examples-")
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def start_daemon(self, extra_yaml=UP):
        self.daemon = Daemon(extra_yaml, data_roots=[os.path.join(SOURCE_DIR, "sample_clouds")])
        self.addCleanup(self.daemon.cleanup)
        return self.daemon.port

    def test_the_planner_sees_the_table_and_the_cup_the_ingest_script_adds(self):
        render("cup_added", self.tmp, frames=12)
        port = self.start_daemon()
        before = example("ingest_folder.py", os.path.join(self.tmp, "before"), "--port", port, "--token-file", self.daemon.token_file)
        self.assertEqual(before.returncode, 0, before.stderr)
        self.assertEqual(before.stdout.count("frame-"), 12)
        self.assertIn("frame-000011: ", before.stdout)
        self.assertEqual(before.stdout.count(" 0 events"), 12, "nothing changes before the cup")

        planner = subprocess.Popen([sys.executable, os.path.join(EXAMPLES_DIR, "planner.py"), "--port", str(port),
                                    "--wait", "120"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.addCleanup(lambda: (planner.kill(), planner.wait(), planner.stdout.close(), planner.stderr.close()))
        lines = []
        waiting = threading.Event()

        def read():
            for line in planner.stdout:
                lines.append(line)
                if line.startswith("waiting for a change"):
                    waiting.set()
        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        self.assertTrue(waiting.wait(60), "the planner did not start waiting: " + "".join(lines))
        self.assertRegex(lines[0], r"^table: plane \d+ \(height 0\.75\d m\), (\d+) of \1 objects stand on it")
        self.assertGreaterEqual(sum(1 for line in lines if line.startswith("  object ")), 3, "box, can and ball")

        after = example("ingest_folder.py", os.path.join(self.tmp, "after"), "--port", port, "--token-file", self.daemon.token_file)
        self.assertEqual(after.returncode, 0, after.stderr)
        self.assertIn("OBJECT_ADDED", after.stdout)
        self.assertEqual(planner.wait(120), 0, planner.stderr.read())
        reader.join(10)
        out = "".join(lines)
        event = re.search(r"^event 1: OBJECT_ADDED at \((\S+), (\S+), \S+\) m", out, re.M)
        self.assertIsNotNone(event, out)
        self.assertLess(math.hypot(float(event.group(1)) - CUP_XY[0], float(event.group(2)) - CUP_XY[1]), 0.10)
        # Asked again after the event, the list holds the cup where it was put.
        after_event = out[event.end():]
        listed = [(float(x), float(y)) for x, y in re.findall(r"^  object \d+: at \((\S+), (\S+), \S+\)", after_event, re.M)]
        self.assertTrue(any(math.hypot(x - CUP_XY[0], y - CUP_XY[1]) < 0.05 for x, y in listed), out)

    def test_ingest_folder_of_cloud_files_goes_through_ingest_file(self):
        # The PCD is in its camera frame (no pose), so no up vector for the world either.
        port = self.start_daemon(extra_yaml="")
        result = example("ingest_folder.py", os.path.join(SOURCE_DIR, "sample_clouds"), "--port", port, "--token-file", self.daemon.token_file)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertRegex(result.stdout, r"^tabletop\.pcd: \d+ points, \d+ planes, 4 objects, 0 events")

    def test_the_examples_name_what_went_wrong(self):
        port = self.start_daemon()
        outside = example("ingest_folder.py", self.tmp, "--port", port, "--token-file", self.daemon.token_file)
        self.assertEqual(outside.returncode, 1)
        self.assertIn("no frame-NNNNNN.color.png, .pcd or .ply files", outside.stderr)
        self.daemon.stop()
        planner = example("planner.py", "--port", port, "--wait", "1")
        self.assertEqual(planner.returncode, 1)
        self.assertIn("cannot connect", planner.stderr)


if __name__ == "__main__":
    unittest.main()
