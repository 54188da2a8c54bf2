"""RGB-D frames into IngestFrame messages, with nothing but the standard library.

``read_png`` decodes the PNGs of recordings (8- or 16-bit grey, RGB or RGBA, not interlaced);
``frame_message`` back-projects a depth image with its colour into an organized cloud;
``images_message`` sends the images as they are instead (``IngestFrame.rgbd``: the daemon
back-projects them; 5 bytes a pixel on the wire against 15, and a copy of the depth instead of a
back-projection in Python: a redkitchen frame takes 0.27 s instead of 0.34 s, most of it the PNG
decoding); ``Sequence`` reads a folder in the 7-Scenes layout the CLI reads
(``frame-NNNNNN.color.png``, ``frame-NNNNNN.depth.png``, ``frame-NNNNNN.pose.txt``,
``camera-intrinsics.txt`` and optionally ``depth-scale.txt``, metres per depth unit).

Pure Python is slow: decoding the PNGs and back-projecting take 0.2-0.5 s per VGA frame (the
redkitchen frames take 0.44 s). It is meant for examples and small recordings; ``scenewatch ingest DIR`` (C++) reads every layout the daemon's CLI knows, fast.
"""

import array
import math
import os
import re
import struct
import sys
import zlib

from . import scenewatch_pb2 as pb

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_CHANNELS = {0: 1, 2: 3, 6: 4}  # PNG colour type -> samples per pixel


class Image:
    """A decoded image: ``width``, ``height``, ``channels`` and ``samples`` (row-major, one int
    per sample: 0..255 for 8-bit files, 0..65535 for 16-bit ones)."""

    def __init__(self, width, height, channels, bit_depth, samples):
        self.width, self.height, self.channels, self.bit_depth, self.samples = width, height, channels, bit_depth, samples


def read_png(path):
    """Decodes a PNG file; ValueError naming the file for anything it cannot read."""
    with open(path, "rb") as f:
        data = f.read()
    if not data.startswith(_PNG_SIGNATURE):
        raise ValueError(f"'{path}': not a PNG file")
    pos, header, idat = 8, None, []
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if len(body) != length:
            raise ValueError(f"'{path}': truncated {kind.decode('latin-1')} chunk")
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if header is None or not idat:
        raise ValueError(f"'{path}': no image header or no image data")
    width, height, bit_depth, colour_type, _, _, interlace = header
    if colour_type not in _CHANNELS or bit_depth not in (8, 16) or interlace != 0:
        raise ValueError(f"'{path}': unsupported PNG (colour type {colour_type}, {bit_depth}-bit, "
                         f"interlace {interlace}); 8/16-bit grey, RGB or RGBA, not interlaced")
    channels = _CHANNELS[colour_type]
    bpp = channels * bit_depth // 8
    stride = width * bpp
    try:
        raw = zlib.decompress(b"".join(idat))
    except zlib.error as e:
        raise ValueError(f"'{path}': corrupt image data ({e})") from e
    if len(raw) != height * (stride + 1):
        raise ValueError(f"'{path}': image data is {len(raw)} bytes, expected {height * (stride + 1)}")
    out = bytearray(height * stride)
    prev = bytearray(stride)
    for y in range(height):
        filter_type = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if filter_type == 1:  # Sub
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 0xFF
        elif filter_type == 2:  # Up
            line = bytearray((a + b) & 0xFF for a, b in zip(line, prev))
        elif filter_type == 3:  # Average
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 0xFF
        elif filter_type == 4:  # Paeth
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b = prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb_, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb_ and pa <= pc else b if pb_ <= pc else c)) & 0xFF
        elif filter_type != 0:
            raise ValueError(f"'{path}': row {y} has unknown filter type {filter_type}")
        out[y * stride:(y + 1) * stride] = line
        prev = line
    if bit_depth == 16:
        samples = array.array("H", bytes(out))
        if sys.byteorder == "little":
            samples.byteswap()  # PNG stores 16-bit samples big-endian
    else:
        samples = out
    return Image(width, height, channels, bit_depth, samples)


def read_numbers(path):
    """Every whitespace-separated number of a small text file ('#' starts a comment)."""
    values = []
    with open(path) as f:
        for line_no, line in enumerate(f, 1):
            for token in line.split("#", 1)[0].split():
                try:
                    values.append(float(token))
                except ValueError:
                    raise ValueError(f"'{path}' line {line_no}: '{token}' is not a number") from None
    return values


def frame_message(color, depth, K, depth_scale_m=0.001, T_world_camera=None, stamp_s=0.0, source=""):
    """A pb.IngestFrame from decoded colour and depth images (``Image``), pinhole intrinsics
    ``K = (fx, fy, cx, cy)``, metres per depth unit and an optional 4x4 camera-to-world pose.
    Depth 0 and 65535 mean "no depth" (NaN points)."""
    _check_images(color, depth)
    fx, fy, cx, cy = K
    w, h = depth.width, depth.height
    nan = math.nan
    xyz = array.array("f", bytes(12 * w * h))
    d = depth.samples
    for v in range(h):
        ry = (v - cy) / fy
        base = v * w
        for u in range(w):
            i = base + u
            raw = d[i]
            if raw == 0 or raw == 65535:
                xyz[3 * i] = xyz[3 * i + 1] = xyz[3 * i + 2] = nan
                continue
            z = raw * depth_scale_m
            xyz[3 * i] = (u - cx) / fx * z
            xyz[3 * i + 1] = ry * z
            xyz[3 * i + 2] = z
    if sys.byteorder != "little":
        xyz.byteswap()
    rgb = _rgb_bytes(color)
    message = pb.IngestFrame(
        cloud=pb.Cloud(width=w, height=h, xyz=xyz.tobytes(), rgb=rgb),
        intrinsics=pb.Intrinsics(fx=fx, fy=fy, cx=cx, cy=cy, width=w, height=h),
        stamp_s=stamp_s, source=source)
    if T_world_camera is not None:
        message.pose.CopyFrom(pb.Pose(matrix=[float(x) for row in T_world_camera for x in row]))
    return message


def _check_images(color, depth):
    if (color.width, color.height) != (depth.width, depth.height):
        raise ValueError(f"colour ({color.width}x{color.height}) and depth ({depth.width}x{depth.height}) sizes differ")
    if depth.channels != 1 or depth.bit_depth != 16:
        raise ValueError("depth must be a 16-bit single-channel image")
    if color.channels not in (3, 4) or color.bit_depth != 8:
        raise ValueError("colour must be an 8-bit RGB or RGBA image")


def _rgb_bytes(color):
    return bytes(color.samples) if color.channels == 3 else bytes(b for i, b in enumerate(color.samples) if i % 4 != 3)


def images_message(color, depth, K, depth_scale_m=0.001, T_world_camera=None, stamp_s=0.0, source=""):
    """A pb.IngestFrame that carries the images (``rgbd``) for the daemon to back-project, with
    the same arguments and meaning as ``frame_message``. Depth is sent in millimetres: other units
    are converted (rounded); 0 and 65535 mean "no depth"."""
    _check_images(color, depth)
    fx, fy, cx, cy = K
    w, h = depth.width, depth.height
    if depth_scale_m == 0.001:
        mm = array.array("H", (0 if raw == 65535 else raw for raw in depth.samples))
    else:
        k = depth_scale_m * 1000.0
        mm = array.array("H", (0 if raw in (0, 65535) or not 0 < round(raw * k) < 65535 else round(raw * k)
                               for raw in depth.samples))
    if sys.byteorder != "little":
        mm.byteswap()
    message = pb.IngestFrame(
        rgbd=pb.RgbdImages(width=w, height=h, depth_mm=mm.tobytes(), rgb=_rgb_bytes(color)),
        intrinsics=pb.Intrinsics(fx=fx, fy=fy, cx=cx, cy=cy, width=w, height=h),
        stamp_s=stamp_s, source=source)
    if T_world_camera is not None:
        message.pose.CopyFrom(pb.Pose(matrix=[float(x) for row in T_world_camera for x in row]))
    return message


class Sequence:
    """A sequence folder in the 7-Scenes layout (PNG colour): ``len()`` frames, ``frame(i)`` the
    pb.IngestFrame of frame i, ``names`` their names ("frame-000000"). With ``send_images``, a
    frame carries the images (``images_message``) instead of a cloud (``frame_message``)."""

    _FRAME = re.compile(r"^(frame-\d+)\.color\.png$")

    def __init__(self, folder, depth_scale_m=None, send_images=False):
        self.folder = folder
        self.send_images = send_images
        self.names = sorted(m.group(1) for m in map(self._FRAME.match, os.listdir(folder)) if m)
        if not self.names:
            raise ValueError(f"'{folder}': no frame-NNNNNN.color.png files; not a sequence folder")
        k = read_numbers(os.path.join(folder, "camera-intrinsics.txt"))
        if len(k) != 9:
            raise ValueError(f"'{folder}/camera-intrinsics.txt': expected a 3x3 camera matrix (9 numbers), found {len(k)}")
        self.K = (k[0], k[4], k[2], k[5])
        scale_file = os.path.join(folder, "depth-scale.txt")
        if depth_scale_m is None and os.path.exists(scale_file):
            values = read_numbers(scale_file)
            if len(values) != 1 or not values[0] > 0:
                raise ValueError(f"'{scale_file}': expected one number > 0 (metres per depth unit)")
            depth_scale_m = values[0]
        self.depth_scale_m = depth_scale_m or 0.001

    def __len__(self):
        return len(self.names)

    def frame(self, index, stamp_s=None):
        name = self.names[index]
        base = os.path.join(self.folder, name)
        pose = None
        if os.path.exists(base + ".pose.txt"):
            m = read_numbers(base + ".pose.txt")
            if len(m) != 16:
                raise ValueError(f"'{base}.pose.txt': expected a 4x4 matrix (16 numbers), found {len(m)}")
            pose = [m[0:4], m[4:8], m[8:12], m[12:16]]
        make = images_message if self.send_images else frame_message
        return make(read_png(base + ".color.png"), read_png(base + ".depth.png"), self.K,
                    self.depth_scale_m, pose, index / 30.0 if stamp_s is None else stamp_s, base)
