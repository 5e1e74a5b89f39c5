"""The peers of `cargo xtask bench visibility`: the same occlusion rays through Mitsuba 3
(`llvm_ad_rgb`, whose ray tracing is Embree) and Open3D (`RaycastingScene`, Embree), on the
same number of threads.

Reads, per case, `DIR/CASE.tris.npy` (f32 [3T, 3], a triangle soup in the engine's centred
coordinates), `DIR/CASE.origins.npy` and `DIR/CASE.dirs.npy` (f32 [R, 3]: every receiver vertex
pushed off its surface along its normal, towards every direction with n·l > 0 — the rays the
`cpu` backend casts). Prints one JSON line per case and peer: the scene build time, the median
trace time over the repetitions and the occluded-ray count (the cross-check against M).

Usage: visibility_peers.py DIR THREADS REPEATS CASE…
"""

import json
import os
import sys
import time

import numpy as np


def median(values):
    return float(np.median(np.array(values)))


def mitsuba_case(tris, origins, dirs, threads, repeats):
    import drjit as dr
    import mitsuba as mi

    dr.set_thread_count(threads)
    mi.set_variant("llvm_ad_rgb")
    start = time.perf_counter()
    mesh = mi.Mesh("m", vertex_count=len(tris), face_count=len(tris) // 3)
    params = mi.traverse(mesh)
    params["vertex_positions"] = dr.ravel(mi.Point3f(tris[:, 0], tris[:, 1], tris[:, 2]))
    params["faces"] = dr.ravel(mi.Vector3u(np.arange(0, len(tris), 3, dtype=np.uint32),
                                           np.arange(1, len(tris), 3, dtype=np.uint32),
                                           np.arange(2, len(tris), 3, dtype=np.uint32)))
    params.update()
    scene = mi.load_dict({"type": "scene", "mesh": mesh})
    dr.eval()
    build = time.perf_counter() - start
    o = mi.Point3f(origins[:, 0], origins[:, 1], origins[:, 2])
    d = mi.Vector3f(dirs[:, 0], dirs[:, 1], dirs[:, 2])
    dr.eval(o, d)
    times, occluded = [], 0
    for _ in range(repeats + 1):
        start = time.perf_counter()
        hit = scene.ray_test(mi.Ray3f(o, d))
        dr.eval(hit)
        count = int(dr.count(hit)[0]) if hasattr(dr.count(hit), "__getitem__") else int(dr.count(hit))
        times.append(time.perf_counter() - start)
        occluded = count
    # The first call compiles the kernel: left out.
    return build, median(times[1:]), occluded


def open3d_case(tris, origins, dirs, threads, repeats):
    import open3d as o3d

    start = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene(nthreads=threads)
    indices = np.arange(len(tris), dtype=np.uint32).reshape(-1, 3)
    scene.add_triangles(o3d.core.Tensor(tris), o3d.core.Tensor(indices))
    build_call = time.perf_counter() - start
    rays = o3d.core.Tensor(np.hstack([origins, dirs]).astype(np.float32))
    times, occluded = [], 0
    for _ in range(repeats + 1):
        start = time.perf_counter()
        hit = scene.test_occlusions(rays, nthreads=threads).numpy()
        times.append(time.perf_counter() - start)
        occluded = int(hit.sum())
    # Open3D commits (builds) its BVH lazily on the first query: that call's excess is build.
    build = build_call + max(times[0] - median(times[1:]), 0.0)
    return build, median(times[1:]), occluded


def main():
    folder, threads, repeats = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    for case in sys.argv[4:]:
        tris = np.load(os.path.join(folder, f"{case}.tris.npy"))
        origins = np.load(os.path.join(folder, f"{case}.origins.npy"))
        dirs = np.load(os.path.join(folder, f"{case}.dirs.npy"))
        for name, run in [("mitsuba3", mitsuba_case), ("open3d", open3d_case)]:
            try:
                build, trace, occluded = run(tris, origins, dirs, threads, repeats)
                row = {"case": case, "peer": name, "build_s": build, "trace_s": trace,
                       "occluded": occluded, "rays": len(origins)}
            except Exception as e:  # a peer that is not installed is reported, not fatal
                row = {"case": case, "peer": name, "error": f"{type(e).__name__}: {e}"}
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
