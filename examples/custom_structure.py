"""A structure from a mesh file: the default bridge written as an STL (with trimesh), then
flown instead of the scenario's boxes. Any STL, OBJ or PLY in metres in the world's ENU
frame works the same way; `mission plan` plans the supports' paths for a new structure.

    python examples/custom_structure.py [--out DIR]
"""

import argparse
from pathlib import Path

import trimesh

from mission import run

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="example-output/custom-structure")
parser.add_argument("--quick", action="store_true", help="cut every run at 40 s (a test)")
args = parser.parse_args()
out = Path(args.out).resolve()
out.mkdir(parents=True, exist_ok=True)

boxes = {  # (min, max) corners, metres
    "deck": ((-20.0, -5.0, 8.0), (20.0, 5.0, 9.0)),
    "pier-west": ((-17.0, -3.0, 0.0), (-15.0, 3.0, 8.0)),
    "pier-east": ((15.0, -3.0, 0.0), (17.0, 3.0, 8.0)),
}
parts = []
for low, high in boxes.values():
    box = trimesh.creation.box(bounds=[low, high])
    parts.append(box)
bridge = trimesh.util.concatenate(parts)
mesh = out / "bridge.stl"
bridge.export(mesh)
print(f"wrote {mesh}: {len(bridge.faces)} triangles")

r = run(
    "along",
    seed=0,
    overrides={
        "world.structure.mesh_file": str(mesh),
        "world.structure.primitives": [],
        "run.timeout_s": 40.0 if args.quick else 900.0,
    },
    out=out / "run",
    force=True,
)
print(f"flew {r.summary.control_cycles} cycles around the mesh; contacts {r.summary.contacts}")
