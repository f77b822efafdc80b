"""Writes rock.obj, the rock of scenarios/seabed_landing.toml: an icosphere (trimesh,
2 subdivisions, 162 vertices) of radius 0.35 m, each vertex moved along its radius by a
seeded random factor in [0.75, 1.15], the underside flattened at z = -0.15 m, so that the
rock sits on the seabed. Run: .venv/bin/python scenarios/meshes/make_rock.py"""

from pathlib import Path

import numpy as np
import trimesh

SEED = 20


def rock() -> trimesh.Trimesh:
    rng = np.random.default_rng(SEED)
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=0.35)
    vertices = mesh.vertices * rng.uniform(0.75, 1.15, size=(len(mesh.vertices), 1))
    vertices[:, 2] = np.maximum(vertices[:, 2], -0.15)
    return trimesh.Trimesh(vertices, mesh.faces, process=True)


if __name__ == "__main__":
    out = Path(__file__).with_name("rock.obj")
    rock().export(out)
    print(f"wrote {out}")
