"""Stops a build of the package that lacks the files the CMake build generates, with the way to
get them; pyproject.toml says everything else."""

import os
import sys

from setuptools import setup

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATED = ("scenewatch_pb2.py", "_version.py")

missing = [name for name in GENERATED if not os.path.isfile(os.path.join(HERE, "scenewatch", name))]
if missing:
    sys.exit(f"scenewatch client: {', '.join('scenewatch/' + m for m in missing)} missing in {HERE}: the CMake build "
             "generates them (from proto/scenewatch.proto and project()'s version). Build (scripts/build), then "
             "install from the build tree: pip install --no-build-isolation --no-index build/clients/python")
setup()
