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
standard output with one timed trace (`trace_s`) and the occluded-ray count. The first request
for a (case, peer) pair also builds its scene (`build_s`) and traces once untimed: Mitsuba
compiles its kernel there, Open3D builds its BVH lazily on its first query (that call's excess
over the timed one is counted as build). A new case drops the previous case's scenes. A peer
that cannot run answers `error`.

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

        self.dr, self.mi = dr, mi
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
        self.scene = mi.load_dict({"type": "scene", "mesh": mesh})
        dr.eval()
        self.build_s = time.perf_counter() - start
        self.o = mi.Point3f(origins[:, 0], origins[:, 1], origins[:, 2])
        self.d = mi.Vector3f(dirs[:, 0], dirs[:, 1], dirs[:, 2])
        dr.eval(self.o, self.d)
        # The first call compiles the kernel: untimed.
        self.trace()

    def trace(self):
        dr, mi = self.dr, self.mi
        start = time.perf_counter()
        hit = self.scene.ray_test(mi.Ray3f(self.o, self.d))
        dr.eval(hit)
        count = dr.count(hit)
        count = int(count[0]) if hasattr(count, "__getitem__") else int(count)
        return time.perf_counter() - start, count


class Open3D:
    def __init__(self, tris, origins, dirs, threads):
        import open3d as o3d

        self.threads = threads
        start = time.perf_counter()
        self.scene = o3d.t.geometry.RaycastingScene(nthreads=threads)
        indices = np.arange(len(tris), dtype=np.uint32).reshape(-1, 3)
        self.scene.add_triangles(o3d.core.Tensor(tris), o3d.core.Tensor(indices))
        build_call = time.perf_counter() - start
        self.rays = o3d.core.Tensor(np.hstack([origins, dirs]).astype(np.float32))
        # Open3D commits (builds) its BVH lazily on the first query: that call's excess over a
        # second one is build.
        first, _ = self.trace()
        second, _ = self.trace()
        self.build_s = build_call + max(first - second, 0.0)

    def trace(self):
        start = time.perf_counter()
        hit = self.scene.test_occlusions(self.rays, nthreads=self.threads).numpy()
        return time.perf_counter() - start, int(hit.sum())


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
                row["build_s"] = scenes[peer].build_s
            trace, occluded = scenes[peer].trace()
            row.update(trace_s=trace, occluded=occluded)
        except Exception as e:  # a peer that is not installed is reported, not fatal
            row["error"] = f"{type(e).__name__}: {e}"
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
