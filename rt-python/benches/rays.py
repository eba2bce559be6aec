"""rtvis.RayMesh against embreex (Embree 4, the library trimesh uses for
rays when it is installed), same mesh, same rays: Mrays/s of first hits
and any hits, best of 5 (embreex called directly, and through trimesh's
``mesh.ray``, as its users call it), and misses on rays aimed exactly at the mesh's
vertices and edge midpoints (each must hit).

    python rt-python/benches/rays.py [--quick] [--csv OUT.csv]

Needs rtvis, trimesh and embreex. rtvis runs once on one thread and once
on all cores (each in a subprocess with ``RAYON_NUM_THREADS``); embreex
traces on the calling thread."""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np


def scenes(quick):
    import trimesh

    level = 5 if quick else 8
    sphere = trimesh.creation.icosphere(subdivisions=level)
    rng = np.random.default_rng(1)
    n = 1 << (16 if quick else 20)
    side = int(np.sqrt(n))
    # Camera-like: a grid of rays from one eye through a square window.
    u, v = np.meshgrid(np.linspace(-0.9, 0.9, side), np.linspace(-0.9, 0.9, side))
    window = np.stack([u.ravel(), v.ravel(), np.zeros(side * side)], axis=1)
    eye = np.array([0.0, 0.0, 3.0])
    primary = (np.repeat(eye[None], side * side, axis=0), window - eye)
    # Random: from anywhere in a box around the mesh, any direction.
    o = rng.uniform(-1.5, 1.5, size=(n, 3))
    d = rng.normal(size=(n, 3))
    random = (o, d / np.linalg.norm(d, axis=1)[:, None])
    # Watertight: through every vertex and edge midpoint, at the centre.
    v = sphere.vertices.astype(np.float32).astype(np.float64)
    e = sphere.edges_unique
    aims = np.concatenate([v, (v[e[:, 0]] + v[e[:, 1]]) / 2])
    return sphere, {"primary": primary, "random": random}, (aims * 3.0, -aims)


def best(f, reps=5):
    out = None
    times = []
    for _ in range(reps):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return min(times), out


def run_rtvis(quick):
    """Rows for rtvis at this process's thread count (a subprocess)."""
    import rtvis

    mesh, sets, (wo, wd) = scenes(quick)
    t_build, m = best(lambda: rtvis.RayMesh(mesh.vertices, mesh.faces), 1)
    rows = []
    for name, (o, d) in sets.items():
        for query, f in (("first", m.intersects_first), ("any", m.intersects_any)):
            secs, _ = best(lambda: f(o, d))
            rows.append((name, query, len(o) / secs / 1e6))
    misses = int((~m.intersects_any(wo, wd)).sum()) + int((m.intersects_first(wo, wd) < 0).sum())
    return {"rows": rows, "misses": misses, "build": t_build}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true")
    p.add_argument("--csv")
    p.add_argument("--rtvis-only", action="store_true", help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.rtvis_only:
        print(json.dumps(run_rtvis(a.quick)))
        return
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    mesh, sets, (wo, wd) = scenes(a.quick)
    ours = {}
    cores = os.cpu_count() or 1
    for threads in (1, cores):
        env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
        out = subprocess.run([sys.executable, __file__, "--rtvis-only"] + (["--quick"] if a.quick else []),
                             capture_output=True, text=True, env=env, check=True)
        ours[threads] = json.loads(out.stdout)
    t = time.perf_counter()
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, mesh.vertices.astype(np.float32)[mesh.faces])
    embree_build = time.perf_counter() - t

    def embree(o, d, query):
        o = np.ascontiguousarray(o, dtype=np.float32)
        d = np.ascontiguousarray(d, dtype=np.float32)
        return scene.run(o, d, query="OCCLUDED" if query == "any" else "INTERSECT")

    # What trimesh users call: mesh.ray with embreex installed.
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    wrapped = RayMeshIntersector(mesh)
    lines = ["rays,query,implementation,mrays_per_s"]
    print(f"{len(mesh.faces)} triangles; build: rtvis {ours[1]['build']:.2f} s, embreex {embree_build:.2f} s")
    print("| rays | query | rtvis 1 thread | rtvis all cores | embreex | trimesh + embreex | rtvis / embreex | "
          "rtvis / trimesh + embreex (1 thread) |")
    print("|---|---|---|---|---|---|---|---|")
    for i, (name, query, one) in enumerate(ours[1]["rows"]):
        o, d = sets[name]
        secs, _ = best(lambda: embree(o, d, query))
        theirs = len(o) / secs / 1e6
        allc = ours[cores]["rows"][i][2]
        ask = wrapped.intersects_first if query == "first" else wrapped.intersects_any
        secs, _ = best(lambda: ask(o, d))
        tm = len(o) / secs / 1e6
        print(f"| {name} | {query} | {one:.2f} | {allc:.2f} ({cores}) | {theirs:.2f} | {tm:.2f} | "
              f"{one / theirs:.2f}× | {one / tm:.2f}× |")
        lines += [f"{name},{query},rtvis,{one:.4f}", f"{name},{query},rtvis-{cores}-threads,{allc:.4f}",
                  f"{name},{query},embreex,{theirs:.4f}", f"{name},{query},trimesh-embreex,{tm:.4f}"]
    hit = embree(wo, wd, "first")
    embree_misses = 2 * int((np.asarray(hit) < 0).sum())
    print(f"watertight: {len(wo)} rays through vertices and edge midpoints, each asked first and any hit; "
          f"misses: rtvis {ours[1]['misses']}, embreex {embree_misses} (first hit only, counted twice)")
    lines.append(f"watertight,first+any,rtvis-misses,{ours[1]['misses']}")
    lines.append(f"watertight,first+any,embreex-misses,{embree_misses}")
    if a.csv:
        with open(a.csv, "w") as fh:
            fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
