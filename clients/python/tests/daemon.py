"""Test support: the real scenewatchd on a free loopback port, and scenario renders.

The binaries come from the environment CTest sets (SCENEWATCHD, SCENEWATCH_SIM, SCENEWATCH_CLI);
PYTHONPATH points at the build tree's package with its generated scenewatch_pb2.py.
"""

import os
import shutil
import subprocess
import tempfile
import threading

SOURCE_DIR = os.environ.get("SCENEWATCH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..", ".."))
EXAMPLES_DIR = os.path.join(SOURCE_DIR, "clients", "python", "examples")


def binary(variable):
    path = os.environ.get(variable)
    if not path or not os.access(path, os.X_OK):
        raise RuntimeError(f"{variable} does not name an executable ({path!r}); run the tests through CTest")
    return path


class Daemon:
    """scenewatchd with a config written to a temporary folder; ``port`` once started. Killed by
    ``stop()`` (SIGTERM, as a user would) or when the test's cleanup runs."""

    def __init__(self, extra_yaml="", data_roots=()):
        self.dir = tempfile.mkdtemp(prefix="scenewatch-py-")
        self.model_dir = os.path.join(self.dir, "model")
        config = os.path.join(self.dir, "scenewatchd.yaml")
        self.token_file = os.path.join(self.dir, "token")  # the daemon creates it (mode 0600)
        roots = ", ".join(data_roots)
        with open(config, "w") as f:
            f.write(f"server:\n  address: 127.0.0.1\n  port: 0\n  model_dir: {self.model_dir}\n"
                    f"  data_roots: [{roots}]\n  token_file: {self.token_file}\n" + extra_yaml)
        self.log_path = os.path.join(self.dir, "scenewatchd.log")
        self._log = open(self.log_path, "w")
        self.process = subprocess.Popen([binary("SCENEWATCHD"), "--config", config, "--port", "0"],
                                        stdout=subprocess.PIPE, stderr=self._log, text=True)
        line = self._readline_within(60)
        prefix = "listening on 127.0.0.1:"
        if not line.startswith(prefix):
            self.stop()
            raise RuntimeError(f"scenewatchd did not say it was listening (got {line!r}); log:\n{self.log()}")
        self.port = int(line[len(prefix):])

    def _readline_within(self, timeout_s):
        result = []
        reader = threading.Thread(target=lambda: result.append(self.process.stdout.readline()), daemon=True)
        reader.start()
        reader.join(timeout_s)
        return result[0].strip() if result else ""

    def log(self):
        self._log.flush()
        with open(self.log_path) as f:
            return f.read()

    def stop(self):
        """SIGTERM and wait; returns the exit code."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(60)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._log.close()
        self.process.stdout.close()
        return self.process.returncode

    def cleanup(self):
        self.stop()
        shutil.rmtree(self.dir, ignore_errors=True)


def render(scenario, out_dir, frames, width=320, height=240):
    """Renders a shipped scenario with scenewatch-sim: one sequence folder per phase under out_dir."""
    subprocess.run([binary("SCENEWATCH_SIM"), "--scenarios", os.path.join(SOURCE_DIR, "sample_clouds", "scenarios"),
                    "render", scenario, "--out", out_dir, "--frames", str(frames),
                    "--width", str(width), "--height", str(height), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
