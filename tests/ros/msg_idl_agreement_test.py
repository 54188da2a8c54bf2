#!/usr/bin/python3
"""ros2/scenewatch_msgs/msg/*.msg (what a ROS 2 workspace builds with rosidl) and
apps/scenewatch-ros/idl/scenewatch_msgs.idl (what the bridge puts on DDS) agree field for field:
the same names, in the same order, of the same types, and the same constants. A ROS 2 node that
subscribes with the rosidl types then reads exactly what the bridge writes.

Usage: msg_idl_agreement_test.py SOURCE_DIR"""
import re
import sys
from pathlib import Path

# rosidl's mapping of .msg primitive types to IDL (rosidl_adapter, msg -> idl).
PRIMITIVES = {
    "bool": "boolean", "byte": "octet", "char": "uint8",
    "float32": "float", "float64": "double",
    "int8": "int8", "uint8": "uint8", "int16": "int16", "uint16": "uint16",
    "int32": "int32", "uint32": "uint32", "int64": "int64", "uint64": "uint64",
    "string": "string",
}


def msg_type_to_idl(msg_type, package):
    """A .msg field type as the IDL the bridge uses spells it (ROS 2's DDS names: pkg::msg::dds_::Type_)."""
    m = re.fullmatch(r"([\w/]+)(\[(\d*)\])?", msg_type)
    if not m:
        raise ValueError(f"unparsed .msg type {msg_type!r}")
    base, array, size = m.group(1), m.group(2), m.group(3)
    if base in PRIMITIVES:
        idl = PRIMITIVES[base]
    else:
        pkg, _, name = base.rpartition("/")
        idl = f"{pkg or package}::msg::dds_::{name}_"
        if not pkg:
            idl = f"{name}_"  # same package and module: the IDL names it unqualified
    if array is None:
        return idl, None
    if size:
        return idl, int(size)
    return f"sequence<{idl}>", None


def parse_msg(path, package):
    fields, constants = [], []
    for raw in path.read_text().splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        m = re.fullmatch(r"(\S+)\s+(\w+)\s*=\s*(\S+)", line)
        if m:
            constants.append((PRIMITIVES[m.group(1)], m.group(2), m.group(3)))
            continue
        m = re.fullmatch(r"(\S+)\s+(\w+)(\s+\S+)?", line)
        if not m:
            raise ValueError(f"{path}: unparsed line {raw!r}")
        idl, size = msg_type_to_idl(m.group(1), package)
        fields.append((idl, m.group(2), size))
    return fields, constants


def parse_idl(path):
    text = re.sub(r"//[^\n]*", "", path.read_text())
    structs = {}
    for m in re.finditer(r"struct\s+(\w+)\s*\{(.*?)\};", text, re.S):
        members = []
        for decl in m.group(2).split(";"):
            decl = " ".join(decl.split())
            if not decl:
                continue
            d = re.fullmatch(r"(.+?)\s+(\w+)(\[(\d+)\])?", decl)
            if not d:
                raise ValueError(f"{path}: unparsed member {decl!r}")
            members.append((d.group(1).replace(" ", ""), d.group(2), int(d.group(4)) if d.group(4) else None))
        structs[m.group(1)] = members
    constants = {}
    for m in re.finditer(r"module\s+(\w+)_Constants\s*\{(.*?)\};", text, re.S):
        constants[m.group(1)] = re.findall(r"const\s+(\w+)\s+(\w+)\s*=\s*([^;]+?)\s*;", m.group(2))
    return structs, constants


def main():
    source = Path(sys.argv[1])
    package = "scenewatch_msgs"
    msgs = sorted((source / "ros2" / package / "msg").glob("*.msg"))
    structs, idl_constants = parse_idl(source / "apps" / "scenewatch-ros" / "idl" / f"{package}.idl")
    failures = []
    if not msgs:
        failures.append("no .msg files")
    for path in msgs:
        name = path.stem
        fields, constants = parse_msg(path, package)
        idl_fields = structs.get(name + "_")
        if idl_fields is None:
            failures.append(f"{name}: no struct {name}_ in the IDL")
            continue
        if fields != idl_fields:
            failures.append(f"{name}: fields differ\n  .msg: {fields}\n  .idl: {idl_fields}")
        if constants != [tuple(c) for c in idl_constants.get(name, [])]:
            failures.append(f"{name}: constants differ\n  .msg: {constants}\n  .idl: {idl_constants.get(name, [])}")
        print(f"{name}: {len(fields)} fields, {len(constants)} constants agree" if not failures else f"{name}: checked")
    extra = set(structs) - {p.stem + "_" for p in msgs}
    if extra:
        failures.append(f"IDL structs without a .msg: {sorted(extra)}")
    if failures:
        print("\n".join(failures), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
