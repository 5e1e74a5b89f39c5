#!/usr/bin/env python3
"""scikit-learn on the clustering crate's benchmark data, next to the crate's own numbers.

Run the Rust side first; it writes the data (.npy) and rust_results.json:

    cargo run --release -p clustering --example compare -- [OUT_DIR]
    .venv/bin/python xtask/scripts/sklearn_compare.py [OUT_DIR] [--quick]

OUT_DIR defaults to target/clustering-compare. Needs numpy and scikit-learn
(python3 -m venv .venv && .venv/bin/pip install numpy scikit-learn).

Budgets matched with examples/compare.rs:
  * PCA: c = 16 and all 80 components of the 81 x 196,608 f32 slot; reconstruction MSE per
    element computed in float64 from transform/inverse_transform. sklearn keeps float32 input in
    float32, so it is also run on the float64 copy.
  * k-means: k = 32, init k-means++, n_init = 1, max_iter = 300, tol = 0 (run until the labels
    are stable, like our tolerance 0), algorithm "lloyd", random_state = 0..4. Inertia is
    recomputed from the returned centers in float64 exactly as on the Rust side.
  * local PCA: no scikit-learn estimator exists, so the same Kambhatla-Leen loop is written here
    with sklearn's KMeans (k-means++, n_init = 1) as the start and sklearn's PCA (full SVD) per
    cluster; k = 10, c = 20, stop at a relative change of the mean error <= 1e-4, max 100 loops.
"""

import json
import os
import sys
import time

import numpy as np
from sklearn.cluster import KMeans
from sklearn.decomposition import PCA


def timed(f, *a, **k):
    t = time.perf_counter()
    r = f(*a, **k)
    return r, time.perf_counter() - t


def nearest_sq(X, C):
    """Squared distance of every row of X to its nearest row of C (float64, chunked)."""
    out = np.empty(X.shape[0])
    for s in range(0, X.shape[0], 4096):
        d = ((X[s:s + 4096, None, :] - C[None, :, :]) ** 2).sum(-1)
        out[s:s + 4096] = d.min(1)
    return out


def pca_rows(X, reps):
    rows = []
    X64 = X.astype(np.float64)
    n_elem = X.size
    for label, c in (("c=16", 16), ("all (80)", 80)):
        for dtype_label, data in (("f32 input", X), ("f64 copy", X64)):
            for solver in (("full", "randomized") if c < 80 else ("full",)):
                times, p = [], None
                for _ in range(reps):
                    p, t = timed(PCA(n_components=c, svd_solver=solver, random_state=0).fit, data)
                    times.append(t)
                rec = p.inverse_transform(p.transform(data)).astype(np.float64)
                mse = float(((X64 - rec) ** 2).sum() / n_elem)
                rows.append(dict(case=f"PCA 81×196,608 f32, {label}", impl=f"scikit-learn PCA {solver}, {dtype_label}",
                                 times=times, metric="MSE/elem", values=[mse], note=""))
    return rows


def kmeans_rows(X, seeds):
    times, values, iters = [], [], []
    for seed in seeds:
        km, t = timed(KMeans(n_clusters=32, init="k-means++", n_init=1, max_iter=300, tol=0.0,
                             algorithm="lloyd", random_state=seed).fit, X)
        times.append(t)
        values.append(float(nearest_sq(X, km.cluster_centers_).sum()))
        iters.append(int(km.n_iter_))
    return [dict(case="k-means 50k×32, k=32", impl="scikit-learn KMeans lloyd", times=times,
                 metric="inertia", values=values, note=f"iterations {iters}")]


def local_pca(X, k, c, tol=1e-4, max_iter=100, seed=0):
    """Kambhatla-Leen local PCA with scikit-learn building blocks."""
    labels = KMeans(n_clusters=k, init="k-means++", n_init=1, random_state=seed).fit(X).labels_
    history = []
    for _ in range(max_iter + 1):
        models = []
        for j in range(k):
            M = X[labels == j]
            if len(M) == 0:
                models.append(None)
                continue
            p = PCA(n_components=min(c, len(M), X.shape[1]), svd_solver="full").fit(M)
            models.append((p.mean_, p.components_))
        errs = np.full((X.shape[0], k), np.inf)
        for j, m in enumerate(models):
            if m is None:
                continue
            D = X - m[0]
            W = D @ m[1].T
            errs[:, j] = (D * D).sum(1) - (W * W).sum(1)
        new = errs.argmin(1)
        err = float(np.maximum(errs[np.arange(len(X)), new], 0).mean())
        history.append(err)
        stable = np.array_equal(new, labels)
        labels = new
        if stable or (len(history) > 1 and abs(history[-2] - err) <= tol * history[-2]):
            break
    return err, len(history) - 1


def local_pca_rows(cases, seeds):
    rows = []
    for name, X in cases:
        times, values, iters = [], [], []
        for seed in seeds:
            (err, it), t = timed(local_pca, X, 10, 20, seed=seed)
            times.append(t)
            values.append(err)
            iters.append(it)
        rows.append(dict(case=f"local PCA {name}, k=10, c=20", impl="scikit-learn KMeans + PCA loop", times=times,
                         metric="mean sq. err/sample", values=values, note=f"iterations {iters}"))
    return rows


def median(v):
    return float(np.median(v)) if len(v) else float("nan")


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    quick = "--quick" in sys.argv
    out = args[0] if args else os.path.join(os.path.dirname(__file__), "..", "..", "target", "clustering-compare")
    reps = 1 if quick else 3
    seeds = range(1 if quick else 5)
    rows = []
    rows += pca_rows(np.load(os.path.join(out, "btf_slot.npy")), reps)
    rows += kmeans_rows(np.load(os.path.join(out, "blobs.npy")), seeds)
    cases = [("trajectories 10,000×600", np.load(os.path.join(out, "trajectories.npy")))]
    chicken = os.path.join(out, "chicken.npy")
    if os.path.exists(chicken):
        X = np.load(chicken)
        cases.append((f"chicken {X.shape[0]}×{X.shape[1]}", X))
    rows += local_pca_rows(cases, seeds)
    with open(os.path.join(out, "sklearn_results.json"), "w") as f:
        json.dump(rows, f, indent=1)

    rust_path = os.path.join(out, "rust_results.json")
    rust = json.load(open(rust_path)) if os.path.exists(rust_path) else []
    ours = {r["case"]: r for r in rust if r["impl"] == "clustering"}
    print("| case | implementation | median time (s) | time / ours | metric | median | min | metric / ours |")
    print("|---|---|---:|---:|---|---:|---:|---:|")
    for r in sorted(rust + rows, key=lambda r: r["case"]):
        o = ours.get(r["case"])
        t, m = median(r["times"]), median(r["values"])
        tr = t / median(o["times"]) if o and o["times"] else float("nan")
        mr = m / median(o["values"]) if o else float("nan")
        print(f"| {r['case']} | {r['impl']} | {t:.3f} | {tr:.2f} | {r['metric']} | {m:.6e} | {min(r['values']):.6e} | {mr:.6f} |")


if __name__ == "__main__":
    main()
