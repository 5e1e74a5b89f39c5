"""The peers of `cargo xtask bench visibility`: the same occlusion rays through Mitsuba 3
(`llvm_ad_rgb`, whose ray tracing is Embree) and Open3D (`RaycastingScene`, Embree), on the
same number of threads.

Reads, per case, `DIR/CASE.tris.npy` (f32 [3T, 3], a triangle soup in the engine's centred
coordinates), `DIR/CASE.origins.npy` and `DIR/CASE.dirs.npy` (f32 [R, 3]: every receiver vertex
pushed off its surface along its normal, towards every direction with n·l > 0 — the rays the
`cpu` backend casts).

Serves requests so that the bench can alternate its own runs with the peers' (on a shared
machine whose speed drifts by a quarter within minutes, a ratio of runs made minutes apart
measures the drift): each line `CASE PEER` on standard input is answered by one JSON line on
standard output with one build of a fresh scene (`build_s`), one timed trace (`trace_s`) and the
occluded-ray count. Every round builds afresh and traces on what it built, so that a round's
total is its own build plus its own trace, as a deforming frame pays. Mitsuba compiles its
kernel on the case's first request (untimed; a new scene reuses it: the first trace on a fresh
bunny scene took 0.30–0.34 s, the second the same). Open3D builds its BVH lazily on a scene's
first query: each round times a new scene's creation and first query (`total_s`, build and
trace) and then a second query (`trace_s`); its build is the difference. A new case drops the
previous case's scenes. A peer that cannot run answers `error`.

Usage: visibility_peers.py DIR THREADS
"""

import json
import os
import sys
import time

import numpy as np


class Mitsuba:
    def __init__(self, tris, origins, dirs, threads):
        import drjit as dr
        import mitsuba as mi

        self.dr, self.mi, self.tris = dr, mi, tris
        dr.set_thread_count(threads)
        mi.set_variant("llvm_ad_rgb")
        self.scene = self.build()
        self.o = mi.Point3f(origins[:, 0], origins[:, 1], origins[:, 2])
        self.d = mi.Vector3f(dirs[:, 0], dirs[:, 1], dirs[:, 2])
        dr.eval(self.o, self.d)
        # The first call compiles the kernel: untimed.
        self.trace()

    def build(self):
        dr, mi, tris = self.dr, self.mi, self.tris
        mesh = mi.Mesh("m", vertex_count=len(tris), face_count=len(tris) // 3)
        params = mi.traverse(mesh)
        params["vertex_positions"] = dr.ravel(mi.Point3f(tris[:, 0], tris[:, 1], tris[:, 2]))
        params["faces"] = dr.ravel(mi.Vector3u(np.arange(0, len(tris), 3, dtype=np.uint32),
                                               np.arange(1, len(tris), 3, dtype=np.uint32),
                                               np.arange(2, len(tris), 3, dtype=np.uint32)))
        params.update()
        scene = mi.load_dict({"type": "scene", "mesh": mesh})
        dr.eval()
        return scene

    def trace(self):
        dr, mi = self.dr, self.mi
        start = time.perf_counter()
        hit = self.scene.ray_test(mi.Ray3f(self.o, self.d))
        dr.eval(hit)
        count = dr.count(hit)
        count = int(count[0]) if hasattr(count, "__getitem__") else int(count)
        return time.perf_counter() - start, count

    def round(self):
        start = time.perf_counter()
        self.scene = self.build()
        build = time.perf_counter() - start
        trace, count = self.trace()
        return {"build_s": build, "trace_s": trace, "occluded": count}


class Open3D:
    def __init__(self, tris, origins, dirs, threads):
        import open3d as o3d

        self.o3d, self.threads, self.tris = o3d, threads, tris
        self.indices = np.arange(len(tris), dtype=np.uint32).reshape(-1, 3)
        self.rays = o3d.core.Tensor(np.hstack([origins, dirs]).astype(np.float32))

    def round(self):
        o3d, rays = self.o3d, self.rays
        start = time.perf_counter()
        scene = o3d.t.geometry.RaycastingScene(nthreads=self.threads)
        scene.add_triangles(o3d.core.Tensor(self.tris), o3d.core.Tensor(self.indices))
        # The BVH is built (committed) by the first query.
        scene.test_occlusions(rays, nthreads=self.threads).numpy()
        total = time.perf_counter() - start
        start = time.perf_counter()
        hit = scene.test_occlusions(rays, nthreads=self.threads).numpy()
        trace = time.perf_counter() - start
        return {"build_s": max(total - trace, 0.0), "trace_s": trace, "total_s": total,
                "occluded": int(hit.sum())}


PEERS = {"mitsuba3": Mitsuba, "open3d": Open3D}


def main():
    folder, threads = sys.argv[1], int(sys.argv[2])
    current, scenes = None, {}
    for line in sys.stdin:
        case, peer = line.split()
        if case != current:
            current, scenes = case, {}
        row = {"case": case, "peer": peer}
        try:
            if peer not in scenes:
                data = [np.load(os.path.join(folder, f"{case}.{part}.npy"))
                        for part in ("tris", "origins", "dirs")]
                scenes[peer] = PEERS[peer](*data, threads)
            row.update(scenes[peer].round())
        except Exception as e:  # a peer that is not installed is reported, not fatal
            row["error"] = f"{type(e).__name__}: {e}"
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
