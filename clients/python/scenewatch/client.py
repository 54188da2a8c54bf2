"""A blocking client of scenewatchd: one TCP connection, one method per call of the protocol.

Framing (see proto/scenewatch.proto): every message is a 4-byte big-endian length followed by one
serialized protobuf message; the client sends ``Request``, the daemon answers ``Response`` with the
request's id, in order. After ``subscribe()`` the daemon also pushes events (``Response`` with id 0
and an ``event``) between the responses; they are kept for ``Subscription`` until read.

NOT thread safe: use one ``Client`` per thread (a planner typically keeps one for calls and one
for its subscription).
"""

import collections
import os
import socket
import struct
import time

from . import scenewatch_pb2 as pb

#: The daemon's default ``server.max_message_bytes``; larger announced lengths are refused.
DEFAULT_MAX_MESSAGE_BYTES = 64 * 1024 * 1024


class Error(Exception):
    """Base class of everything this client raises."""


class StatusError(Error):
    """The daemon refused a request: ``code`` is its ``pb.Status.Code`` value, ``code_name`` the
    name ("INVALID_ARGUMENT"), ``message`` the daemon's message naming the problem."""

    def __init__(self, code, message, call=""):
        self.code = int(code)
        self.code_name = pb.Status.Code.Name(self.code) if self.code in pb.Status.Code.values() else str(code)
        self.message = message
        self.call = call
        where = f"{call}: " if call else ""
        super().__init__(f"{where}{self.code_name}: {message}")


class ConnectionLost(Error, ConnectionError):
    """The connection could not be made, or broke, or the daemon closed it."""


class Timeout(Error, TimeoutError):
    """No answer within the timeout. The connection stays usable: a late answer is skipped."""


def _vec3(v):
    """A pb.Vec3 from a pb.Vec3 or any sequence of three numbers."""
    if isinstance(v, pb.Vec3):
        return v
    x, y, z = v
    return pb.Vec3(x=float(x), y=float(y), z=float(z))


def _box(minimum, maximum):
    return pb.Box(min=_vec3(minimum), max=_vec3(maximum))


def pose_message(T_world_camera):
    """A pb.Pose from a 4x4 matrix (nested sequences, row-major) or 16 numbers; None stays None."""
    if T_world_camera is None or isinstance(T_world_camera, pb.Pose):
        return T_world_camera
    values = [float(x) for row in T_world_camera for x in (row if hasattr(row, "__iter__") else [row])]
    if len(values) != 16:
        raise ValueError(f"a pose is a 4x4 matrix (16 values), got {len(values)}")
    return pb.Pose(matrix=values)


class Subscription:
    """The events pushed on a subscribed connection, oldest first.

    ``last_event_id``: events up to this id happened before the subscription (fetch them with
    ``Client.get_events(since=...)``). Iterating blocks until the next event; ``next(timeout_s)``
    raises ``Timeout`` when none comes in time. When the daemon goes away the iteration raises
    ``ConnectionLost`` (it does not just end: a planner must know it is no longer told).

    ``localization_changes``: a deque of pb.LocalizationResult, one per change of a camera's
    localization state (lost, found, homed; its ``camera`` names it) that arrived while the
    connection waited for an event or a reply, oldest first; pop them as you go.
    """

    def __init__(self, client, last_event_id, timeout_s):
        self._client = client
        self.last_event_id = last_event_id
        self._timeout_s = timeout_s

    @property
    def localization_changes(self):
        return self._client._localization_changes

    def next(self, timeout_s=None):
        """The next event (pb.Event); waits at most timeout_s (None: the subscription's timeout,
        0 or less: forever)."""
        return self._client._next_event(self._timeout_s if timeout_s is None else timeout_s)

    def __iter__(self):
        return self

    def __next__(self):
        return self.next()


DEFAULT_TOKEN_FILE = os.path.join("~", ".scenewatch", "token")


def read_token_file(path=None):
    """The access token in ``path`` (default ~/.scenewatch/token), or None when it cannot be read:
    read-only calls need none, and a refused call says PERMISSION_DENIED."""
    try:
        with open(os.path.expanduser(path or DEFAULT_TOKEN_FILE)) as f:
            return f.read().strip() or None
    except OSError:
        return None


class Client:
    """One connection to scenewatchd.

    ``timeout_s`` bounds each call (connecting included); 0 or None waits forever. Every method
    returns the reply message of its call (``pb.HealthReply``, ``pb.IngestReply``, ...), raises
    ``StatusError`` when the daemon refuses the request, ``Timeout`` when it does not answer in
    time and ``ConnectionLost`` when the connection is gone.
    """

    def __init__(self, host="127.0.0.1", port=7878, timeout_s=30.0, max_message_bytes=DEFAULT_MAX_MESSAGE_BYTES,
                 token=None, token_file=None):
        self.host, self.port = host, int(port)
        # Calls that change the model (ingest, clear_box, reset, save, load) need the daemon's
        # access token: given, or read from its file (default ~/.scenewatch/token, as the CLI).
        self.token = token if token is not None else read_token_file(token_file)
        self.timeout_s = timeout_s
        self.max_message_bytes = max_message_bytes
        self._buffer = bytearray()
        self._events = collections.deque()
        self._localization_changes = collections.deque()
        self._next_id = 1
        try:
            self._sock = socket.create_connection((host, self.port), timeout=timeout_s or None)
        except socket.timeout as e:
            raise Timeout(f"{host}:{port}: no connection within {timeout_s} s") from e
        except OSError as e:
            raise ConnectionLost(f"{host}:{port}: cannot connect ({e.strerror or e}); is scenewatchd running "
                                 "there? Start it with: scenewatchd --config config/scenewatchd.yaml") from e
        self._sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    # -- context manager ------------------------------------------------------------------------
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        """Closes the connection (idempotent)."""
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    @property
    def endpoint(self):
        return f"{self.host}:{self.port}"

    # -- the calls ------------------------------------------------------------------------------
    def health(self):
        """Liveness: pb.HealthReply (version, uptime_s, frames_processed)."""
        return self._call("health", pb.Health())

    def stats(self):
        """Counters of the daemon and its map: pb.StatsReply."""
        return self._call("stats", pb.Stats())

    def get_localization(self, camera=None):
        """Where each camera is: pb.LocalizationReply, one pb.LocalizationResult per camera (state,
        T_world_odom as 16 row-major numbers, the last correction odom_change_m / _deg, quality,
        homed, relocalized). ``camera``: that camera only; StatusError NOT_FOUND when it sent no
        frame since the daemon started or loaded its model ("" names the default camera)."""
        if camera is None:
            return self._call("get_localization", pb.GetLocalization(), result="localization")
        return self._call("get_localization", pb.GetLocalization(camera=camera, only_default=camera == ""),
                          result="localization")

    def ingest_frame(self, frame=None, **fields):
        """Processes one frame: a pb.IngestFrame, or its fields as keywords (cloud=pb.Cloud,
        pose=4x4 matrix or pb.Pose, intrinsics=pb.Intrinsics, stamp_s, source, camera,
        localization="given" | "refine" | "track"). pb.IngestReply; its ``localization`` says
        where the memory placed the frame (``state`` "lost": the frame changed nothing)."""
        if frame is not None and fields:
            raise TypeError("ingest_frame takes a pb.IngestFrame or its fields as keywords, not both")
        if frame is None:
            if "pose" in fields:
                fields["pose"] = pose_message(fields["pose"])
            if isinstance(fields.get("localization"), str):
                modes = {"given": pb.LOCALIZATION_GIVEN, "refine": pb.LOCALIZATION_REFINE, "track": pb.LOCALIZATION_TRACK}
                if fields["localization"] not in modes:
                    raise ValueError("localization must be given, refine or track, not %r" % fields["localization"])
                fields["localization"] = modes[fields["localization"]]
            frame = pb.IngestFrame(**{k: v for k, v in fields.items() if v is not None})
        return self._call("ingest_frame", frame, result="ingest")

    def ingest_file(self, path, pose=None, stamp_s=0.0):
        """Asks the daemon to read a cloud file (.pcd/.ply) under its data_roots. pb.IngestReply."""
        message = pb.IngestFile(path=str(path), stamp_s=stamp_s)
        if pose is not None:
            message.pose.CopyFrom(pose_message(pose))
        return self._call("ingest_file", message, result="ingest")

    def get_planes(self):
        """Supporting planes of the last frame: pb.PlanesReply."""
        return self._call("get_planes", pb.GetPlanes(), result="planes")

    def get_objects(self, describe=False):
        """The tracked objects: pb.ObjectsReply (``.objects``, each with id, box, plane_id, ...; a
        foreground object with ``foreground``, ``pose``, ``free_dofs``, ``frozen_dofs``, ``handlings``).
        ``describe``: also each object's ``ontology`` (class, score, fitted primitive, grasps)."""
        return self._call("get_objects", pb.GetObjects(describe=describe), result="objects")

    def get_hands(self):
        """The hands and the person seen in the last frame: pb.HandsReply (``.hands``, each with
        ``box_world``, ``tip_world``, ``score``; ``person_pixels``, ``person_box_world``)."""
        return self._call("get_hands", pb.GetHands(), result="hands")

    def query_occupancy(self, points=(), box=None):
        """Occupancy of world points (sequences of 3 numbers) and/or a box ((min xyz), (max xyz)).
        pb.OccupancyReply: ``states`` one per point (pb.OCCUPANCY_FREE, ...), ``box`` if asked."""
        message = pb.QueryOccupancy(points=[_vec3(p) for p in points])
        if box is not None:
            message.box.CopyFrom(_box(*box))
        return self._call("query_occupancy", message, result="occupancy")

    def get_pending_changes(self):
        """The changes seen but not yet confirmed (not yet events): pb.PendingChangesReply
        (``.changes``, each with ``id``, ``kind`` pb.PendingChange.ADDED / REMOVED /
        APPEARANCE_CHANGE, ``box_world``, ``centroid_world``, ``hits`` of ``hits_needed``,
        ``camera``). An id is a ``next_best_view(pending_id=...)`` target while it is listed."""
        return self._call("get_pending_changes", pb.GetPendingChanges(), result="pending_changes")

    def next_best_view(self, object_id=None, box=None, event_id=None, workspace=False, measure="", n=5,
                       radius_m=0.0, current_pose=None, pending_id=None):
        """Where to look next: give exactly one target (an object id, a box ((min xyz), (max xyz)),
        an event id, a pending change's id, or workspace=True); a pending change no longer pending
        raises StatusError NOT_FOUND, naming the event that confirmed it when the daemon's log has
        it. pb.NextBestViewReply: ``views`` best first, each with
        ``pose.matrix`` (16 numbers, row-major T_world_camera), ``score``, ``expected_coverage``
        and ``why``; ``target_description`` says what was planned for (for an object a class
        fits: its completed surface, its unseen side included; else its box, and why).
        ``current_pose`` (16 numbers) adds the cost of moving there. ``measure``
        "covariance" (or "covariance_321", "covariance_322") with an object_id: the seed's planner,
        one view on the sphere of radius_m; the daemon checks the name."""
        message = pb.NextBestView(measure=measure, n=n, radius_m=radius_m)
        given = [object_id is not None, box is not None, event_id is not None, pending_id is not None, bool(workspace)]
        if sum(given) != 1:
            raise ValueError("next_best_view: give exactly one of object_id, box, event_id, pending_id, workspace")
        if object_id is not None:
            message.object_id = object_id
        elif box is not None:
            message.box.CopyFrom(_box(*box))
        elif event_id is not None:
            message.event_id = event_id
        elif pending_id is not None:
            message.pending_id = pending_id
        else:
            message.workspace = True
        if current_pose is not None:
            message.current_pose.matrix.extend(float(v) for v in current_pose)
            message.motion_cost_per_m = 0.5
        return self._call("next_best_view", message)

    def clear_box(self, minimum, maximum):
        """Marks the known voxels in a world box free: pb.ClearBoxReply (voxels_changed)."""
        return self._call("clear_box", pb.ClearBox(box=_box(minimum, maximum)))

    def reset(self):
        """Forgets map, keyframes, objects and the event log: pb.ResetReply."""
        return self._call("reset", pb.Reset())

    def save_model(self):
        """Saves the model to the daemon's model directory: pb.SaveModelReply (model_dir)."""
        return self._call("save_model", pb.SaveModel())

    def load_model(self):
        """Reloads the model from the daemon's model directory: pb.LoadModelReply."""
        return self._call("load_model", pb.LoadModel())

    def get_events(self, since=0, max_count=0):
        """Events of the daemon's log with id > since, oldest first (a list of pb.Event)."""
        return list(self._call("get_events", pb.GetEvents(since=since, max_count=max_count), result="events").events)

    def get_surprise_map(self, frame=None, include_channels=False):
        """Image surprise of ``frame`` (a pb.IngestFrame) against the appearance memory, or of the
        last posed frame ingested: pb.SurpriseMapReply (``total`` is float32 per pixel)."""
        message = pb.GetSurpriseMap(include_channels=include_channels)
        if frame is not None:
            message.frame.CopyFrom(frame)
        return self._call("get_surprise_map", message, result="surprise_map")

    def list_classes(self):
        """The daemon's object classes: pb.ListClassesReply (``classes``, each a pb.ObjectClass,
        and ``yaml``, the same as a classes document)."""
        return self._call("list_classes", pb.ListClasses())

    def define_class(self, yaml_text):
        """Adds or replaces classes given as a classes document (config/ontology.yaml's format).
        Needs the token. pb.DefineClassReply (``defined`` names, ``persisted``)."""
        return self._call("define_class", pb.DefineClass(yaml=yaml_text))

    def subscribe(self, timeout_s=0):
        """From now on the daemon pushes every new event on this connection. Returns a
        ``Subscription`` to iterate; ``timeout_s`` is its default wait per event (0: forever)."""
        reply = self._call("subscribe", pb.Subscribe())
        return Subscription(self, reply.last_event_id, timeout_s)

    # -- transport ------------------------------------------------------------------------------
    def _call(self, call, message, result=None):
        request = pb.Request(id=self._next_id)
        if self.token:
            request.token = self.token
        self._next_id += 1
        getattr(request, call).CopyFrom(message)
        self._send(request)
        deadline = self._deadline(self.timeout_s)
        while True:
            response = self._receive(deadline, f"{call} (request {request.id})")
            if response.id == 0:
                self._handle_unsolicited(response, call)
                continue
            if response.id != request.id:
                continue  # the late answer of a call that timed out
            if response.status.code != pb.Status.OK:
                raise StatusError(response.status.code, response.status.message, call)
            return getattr(response, result or call)

    def _next_event(self, timeout_s):
        deadline = self._deadline(timeout_s)
        while not self._events:
            response = self._receive(deadline, "the next event")
            if response.id == 0:
                self._handle_unsolicited(response, "subscribe")
        return self._events.popleft()

    def _handle_unsolicited(self, response, call):
        if response.WhichOneof("result") == "event":
            self._events.append(response.event)
        elif response.WhichOneof("result") == "localization":
            self._localization_changes.extend(response.localization.cameras)
        elif response.status.code != pb.Status.OK:
            # An error without a request id: broken framing, a read timeout, too many clients.
            # The daemon closes the connection after it.
            self.close()
            raise StatusError(response.status.code, response.status.message, call)

    @staticmethod
    def _deadline(timeout_s):
        return time.monotonic() + timeout_s if timeout_s and timeout_s > 0 else None

    def _send(self, request):
        if self._sock is None:
            raise ConnectionLost(f"{self.endpoint}: the connection is closed")
        payload = request.SerializeToString()
        try:
            self._sock.settimeout(self.timeout_s or None)
            self._sock.sendall(struct.pack(">I", len(payload)) + payload)
        except socket.timeout as e:
            raise Timeout(f"{self.endpoint}: the request could not be sent within {self.timeout_s} s") from e
        except OSError as e:
            self.close()
            raise ConnectionLost(f"{self.endpoint}: sending failed ({e})") from e

    def _receive(self, deadline, what):
        """The next Response, whatever its id."""
        while True:
            if len(self._buffer) >= 4:
                (length,) = struct.unpack(">I", self._buffer[:4])
                if length == 0 or length > self.max_message_bytes:
                    self.close()
                    raise ConnectionLost(f"{self.endpoint}: the daemon announced a message of {length} bytes "
                                         f"(limit {self.max_message_bytes}); the stream is broken")
                if len(self._buffer) >= 4 + length:
                    payload = bytes(self._buffer[4:4 + length])
                    del self._buffer[:4 + length]
                    response = pb.Response()
                    try:
                        response.ParseFromString(payload)
                    except Exception as e:  # google.protobuf.message.DecodeError
                        self.close()
                        raise ConnectionLost(f"{self.endpoint}: undecodable response ({e})") from e
                    return response
            if self._sock is None:
                raise ConnectionLost(f"{self.endpoint}: the connection is closed")
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise Timeout(f"{self.endpoint}: no answer for {what} in time")
            try:
                self._sock.settimeout(left)
                chunk = self._sock.recv(1 << 20)
            except socket.timeout as e:
                raise Timeout(f"{self.endpoint}: no answer for {what} in time") from e
            except OSError as e:
                self.close()
                raise ConnectionLost(f"{self.endpoint}: receiving failed ({e})") from e
            if not chunk:
                self.close()
                raise ConnectionLost(f"{self.endpoint}: the daemon closed the connection")
            self._buffer += chunk
