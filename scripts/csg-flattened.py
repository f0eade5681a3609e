#!/usr/bin/env python3
"""Writes a TOML scene with every CSG object replaced by its solids placed as
plain objects (same shapes, materials and transforms; not the same picture),
the comparison for CSG's cost in docs/performance-log.md:

    python3 scripts/csg-flattened.py scenes/csg.toml > /tmp/csg-flattened.toml
    whitted render scenes/csg.toml --threads 1 -o /tmp/csg.png
    whitted render /tmp/csg-flattened.toml --threads 1 -o /tmp/flat.png

With --close, both scenes are written for `whitted bench`, CSG kept or not
(`--keep-csg`): no floor plane and the camera closer, so that most rays
reach the objects:

    python3 scripts/csg-flattened.py scenes/csg.toml --close --keep-csg > /tmp/csg-close.toml
    python3 scripts/csg-flattened.py scenes/csg.toml --close > /tmp/flat-close.toml
    whitted bench /tmp/csg-close.toml --accel bvh --width 320 --height 240

A child's material is its own, else its nearest CSG parent's; its transform
steps come before its parents' (a CSG child is placed in its parent's space).
"""

import sys
import tomllib


def as_list(transform):
    if transform is None:
        return []
    return transform if isinstance(transform, list) else [transform]


def leaves(obj, material, transform):
    """The plain objects of `obj` under a parent's material and transform."""
    material = obj.get("material", material)
    transform = as_list(obj.get("transform")) + transform
    if "csg" not in obj:
        plain = {k: v for k, v in obj.items() if k not in ("material", "transform")}
        if material is not None:
            plain["material"] = material
        if transform:
            plain["transform"] = transform
        return [plain]
    return [leaf for child in obj["children"] for leaf in leaves(child, material, transform)]


def value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, list):
        return "[" + ", ".join(value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
    raise TypeError(v)


def table(name, fields, out):
    out.append(f"[{name}]")
    out.extend(f"{k} = {value(v)}" for k, v in fields.items())
    out.append("")


def main() -> None:
    close, keep = "--close" in sys.argv, "--keep-csg" in sys.argv
    with open(sys.argv[1], "rb") as f:
        scene = tomllib.load(f)
    if close:
        scene["camera"]["eye"] = [0, 2.5, -5.5]
        scene["objects"] = [o for o in scene["objects"] if o.get("shape") != "plane"]
    out = [f"# {sys.argv[1]} with its CSG objects flattened by scripts/csg-flattened.py.", ""]
    for key, fields in scene.items():
        if key == "materials":
            for name, material in fields.items():
                table(f"materials.{name}", material, out)
        elif isinstance(fields, dict):
            table(key, fields, out)
    for light in scene.get("lights", []):
        table("[lights]", light, out)
    for obj in scene.get("objects", []):
        for plain in [obj] if keep else leaves(obj, None, []):
            table("[objects]", plain, out)
    print("\n".join(out))


if __name__ == "__main__":
    main()
