"""Seam Repair's Laplacian against an independent one: the skull's mesh before smoothing (read
from the PLY file the Merged Surface Writer wrote) smoothed here with numpy, in double, by the
rules of vtkWindowedSincPolyDataFilter's stencils (what Seam Repair documents): a vertex whose
edges all have two triangles moves toward all its neighbours; one with exactly two boundary
edges (one triangle), or exactly two non-manifold edges, toward those two unless the path
turns by more than 15 degrees; any other is fixed. Jacobi iterations, the same relaxation and
count. Seam Repair's points (1 to 4 ranks) must equal it: within 1e-6 of the spacing with double
points, within 2 units in the last place with float points.

  python3 TestLaplacianOracle.py --pvbatch pvbatch --mpiexec mpiexec --plugin RGMarchingCubes.so \
      --workdir DIR --ranks 1,2,3,4
"""

import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
import rgmc_testing  # noqa: E402

ITERATIONS = 20
RELAXATION = 0.1


def read_ply(path):
    """Vertices (x, y, z as float32 or float64) and triangles of a binary little-endian PLY."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        body = f.read()
    if "format binary_little_endian 1.0" not in header:
        raise RuntimeError("%s: not a binary little-endian PLY" % path)
    vertices = faces = 0
    fields = []
    element = None
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            element = words[1]
            if element == "vertex":
                vertices = int(words[2])
            else:
                faces = int(words[2])
        elif words[:1] == ["property"] and element == "vertex":
            fields.append((words[2], {"float": "<f4", "double": "<f8"}[words[1]]))
    vertex_type = np.dtype(fields)
    v = np.frombuffer(body, vertex_type, vertices)
    points = np.stack([v["x"], v["y"], v["z"]], axis=1)
    face_type = np.dtype([("n", "u1"), ("i", "<i4", 3)])
    f = np.frombuffer(body, face_type, faces, offset=vertices * vertex_type.itemsize)
    if np.any(f["n"] != 3):
        raise RuntimeError("%s: not triangles" % path)
    return points, f["i"].astype(np.int64)


def stencils(points, triangles):
    """(vertex, neighbour) pairs of every vertex's stencil, sorted by vertex then neighbour."""
    n = len(points)
    half = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    both = np.concatenate([half, half[:, ::-1]])
    pairs, uses = np.unique(both, axis=0, return_counts=True)  # (v, w) sorted, triangles on vw
    v, w = pairs[:, 0], pairs[:, 1]
    total = np.bincount(v, weights=uses, minlength=n)
    boundary = np.bincount(v, weights=uses == 1, minlength=n)
    nonmanifold = np.bincount(v, weights=uses > 2, minlength=n)
    movable = (total > 1) & (total < 2 * 255)
    everyone = movable & (boundary == 0) & (nonmanifold == 0)
    keep = everyone[v]
    # Exactly two boundary (or non-manifold) edges and none of the other kind: along them,
    # unless the path a -> vertex -> b turns by more than 15 degrees (differences taken in the
    # points' type, as VTK does).
    cos_angle = np.cos(np.radians(15.0))
    for kind, other, special in ((boundary, nonmanifold, uses == 1), (nonmanifold, boundary, uses > 2)):
        chosen = movable & (kind == 2) & (other == 0)
        rows = np.nonzero(chosen[v] & special)[0]
        for vertex in np.unique(v[rows]):
            a, b = w[rows[v[rows] == vertex]]
            l1 = (points[vertex] - points[a]).astype(np.float64)
            l2 = (points[b] - points[vertex]).astype(np.float64)
            l1 = l1 / (np.linalg.norm(l1) or 1.0)
            l2 = l2 / (np.linalg.norm(l2) or 1.0)
            if np.dot(l1, l2) >= cos_angle:
                keep[rows[v[rows] == vertex]] = True
    special = int(np.count_nonzero(movable & ~everyone))
    return v[keep], w[keep], special


def jacobi(points, v, w):
    x = points.astype(np.float64)
    count = np.bincount(v, minlength=len(x)).astype(np.float64)
    moving = count > 0
    for _ in range(ITERATIONS):
        delta = np.zeros_like(x)
        np.add.at(delta, v, x[w] - x[v])  # in the order of v, then w: increasing global id
        step = x.copy()
        step[moving] = x[moving] + RELAXATION * delta[moving] / count[moving, None]
        x = step
    return x


def main():
    args = rgmc_testing.mpi_driver_arguments("1,2,3,4")
    script = rgmc_testing.in_paraview("LaplacianMeshes.py")
    env = rgmc_testing.mpi_environment()
    failures = 0
    for ranks in [int(r) for r in args.ranks.split(",")]:
        prefix = os.path.join(args.workdir, "skull-%d" % ranks)
        command = [args.pvbatch, script, "--plugin", args.plugin, "--prefix", prefix,
                   "--iterations", str(ITERATIONS), "--relaxation", str(RELAXATION)]
        if ranks > 1:
            command = rgmc_testing.mpiexec_command(args.mpiexec, ranks) + [args.pvbatch, "--mpi"] + command[1:]
        print("+ " + " ".join(command), flush=True)
        result = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
        if result.returncode != 0:
            print(result.stdout + result.stderr[-3000:], file=sys.stderr)
            print("FAILED: %d ranks: exit %d" % (ranks, result.returncode))
            failures += 1
            continue
        for precision in ("single", "double"):
            before, triangles = read_ply("%s-%s-input.ply" % (prefix, precision))
            after, triangles_after = read_ply("%s-%s-smoothed.ply" % (prefix, precision))
            with open(prefix + "-spacing.txt") as f:
                spacing = float(f.read())
            v, w, special = stencils(before, triangles)
            oracle = jacobi(before, v, w)
            moved = np.abs(after.astype(np.float64) - before.astype(np.float64)).max()
            if precision == "double":
                error = np.abs(after - oracle).max()
                ok = error <= 1e-6 * spacing
                detail = "max difference %.3g (limit %.3g)" % (error, 1e-6 * spacing)
            else:
                rounded = oracle.astype(np.float32)
                # Units in the last place of the float nearest the oracle.
                ulps = np.abs(after.astype(np.float64) - rounded) / np.spacing(np.abs(rounded)).astype(np.float64)
                worst = float(ulps.max())
                exact = int(np.count_nonzero(after == rounded))
                ok = worst <= 2
                detail = "max %.2f ulps, %d of %d coordinates equal to the rounded oracle" % (worst, exact, after.size)
            ok = ok and np.array_equal(triangles, triangles_after) and moved > 1e-3 * spacing
            fixed = len(before) - len(np.unique(v))
            # The rules beyond "all neighbours" must be exercised: boundary vertices, and fixed ones.
            ok = ok and special > 0 and fixed > 0
            print("%d ranks, %s points: %d vertices (%d on boundary or non-manifold edges, %d fixed), "
                  "%d triangles, moved up to %.3g: %s: %s" % (ranks, precision, len(before), special, fixed,
                                                             len(triangles), moved, detail, "ok" if ok else "FAILED"))
            failures += 0 if ok else 1
    print("TestLaplacianOracle: %d failures" % failures)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
