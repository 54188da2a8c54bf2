"""Python client of scenewatchd, the scenewatch perception service.

    import scenewatch
    with scenewatch.Client("127.0.0.1", 7878, timeout_s=10) as client:
        for obj in client.get_objects().objects:
            print(obj.id, obj.centroid)

The messages are those of proto/scenewatch.proto, generated at build time into
``scenewatch.scenewatch_pb2`` (also reachable as ``scenewatch.pb``). ``__version__`` is the
project's version (CMakeLists.txt's project()), the daemon's ``HealthReply.version`` of the same
release.
"""

from ._version import __version__
from . import scenewatch_pb2 as pb
from .client import Client, ConnectionLost, Error, StatusError, Subscription, Timeout, pose_message

__all__ = ["__version__", "pb", "Client", "ConnectionLost", "Error", "StatusError", "Subscription", "Timeout", "pose_message"]
