"""Seed 004's translucency model against Mitsuba 3's volumetric path tracer (`cargo xtask
compare translucency`).

For each mesh and light: the same camera, point light and medium (Jensen et al. 2001's skin1,
σ_a and σ′_s per mm, an isotropic phase function so σ_s = σ′_s) are rendered by

* Mitsuba 3 (`scalar_rgb`, `volpath`): a homogeneous medium inside an index-matched (null)
  boundary — a point light cannot be reached through a smooth dielectric by next-event
  estimation, so both renderers use η = 1 (no Fresnel, no refraction);
* cloth-vis with the `translucency` effect (direct Lambert term with the dipole's R_d + eq. 12);
* cloth-vis with the effect's term switched off (intensity 0): plain diffuse shading, R_d.

It reports, over the pixels both renderers cover, the relative luminance error (L1 and RMS,
relative to the reference's mean) and SSIM of the display-mapped luminance, and writes a
picture per case: ours | Mitsuba | plain diffuse | |ours − Mitsuba| (false colour).

Usage: mitsuba_translucency.py CLOTH_VIS OUT_DIR DATA_DIR [--quick]
"""

import json
import subprocess
import sys
import time
from pathlib import Path

import mitsuba as mi
import numpy as np
from PIL import Image

mi.set_variant("scalar_rgb")

# Jensen et al. 2001, skin1 (mm⁻¹).
SIGMA_S = np.array([0.74, 0.88, 1.01])
SIGMA_A = np.array([0.032, 0.17, 0.48])
MM_PER_UNIT = 1000.0
INTENSITY = 0.02  # W/sr of the point light


def luminance(rgb):
    return 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]


def read_exr(path):
    bitmap = mi.Bitmap(str(path))
    return np.array(bitmap, dtype=np.float64)


def gaussian_filter(img, sigma=1.5, radius=5):
    x = np.arange(-radius, radius + 1)
    k = np.exp(-(x**2) / (2 * sigma**2))
    k /= k.sum()
    out = np.apply_along_axis(lambda r: np.convolve(r, k, mode="same"), 0, img)
    return np.apply_along_axis(lambda r: np.convolve(r, k, mode="same"), 1, out)


def ssim_map(a, b):
    c1, c2 = 0.01**2, 0.03**2
    mu_a, mu_b = gaussian_filter(a), gaussian_filter(b)
    va = gaussian_filter(a * a) - mu_a**2
    vb = gaussian_filter(b * b) - mu_b**2
    cov = gaussian_filter(a * b) - mu_a * mu_b
    return ((2 * mu_a * mu_b + c1) * (2 * cov + c2)) / ((mu_a**2 + mu_b**2 + c1) * (va + vb + c2))


def display(rgb, scale):
    return np.clip(rgb * scale, 0, 1) ** (1 / 2.2)


def mitsuba_render(mesh, camera, light, size, spp):
    sigma_t = SIGMA_A + SIGMA_S
    peak = sigma_t.max()
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "volpath", "max_depth": -1},
            "sensor": {
                "type": "perspective",
                "fov": camera["fov_deg"],
                "fov_axis": "y",
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=camera["eye"], target=camera["target"], up=[0, 1, 0]
                ),
                "film": {
                    "type": "hdrfilm",
                    "width": size,
                    "height": size,
                    "rfilter": {"type": "box"},
                    "pixel_format": "rgba",
                },
                "sampler": {"type": "independent", "sample_count": spp},
            },
            "light": {
                "type": "point",
                "position": light,
                "intensity": {"type": "rgb", "value": [INTENSITY] * 3},
            },
            "object": {
                "type": "ply",
                "filename": str(mesh),
                "bsdf": {"type": "null"},
                "interior": {
                    "type": "homogeneous",
                    "albedo": {"type": "rgb", "value": (SIGMA_S / sigma_t).tolist()},
                    # Mitsuba reads an RGB σ_t as a reflectance in [0, 1]: normalise, scale back.
                    "sigma_t": {"type": "rgb", "value": (sigma_t / peak).tolist()},
                    "scale": MM_PER_UNIT * peak,
                },
            },
        }
    )
    start = time.time()
    image = np.array(mi.render(scene), dtype=np.float64)
    return image, time.time() - start


def ours_render(cloth_vis, mesh, camera, light, size, out_dir, name, intensity):
    scene = f"""
name = "{name}"
effects = ["translucency"]

[[object]]
name = "object"
source = "{mesh}"

[camera]
eye = {list(camera["eye"])}
target = {list(camera["target"])}
fov_deg = {camera["fov_deg"]}
width = {size}
height = {size}

[translucency]
sigma_a = {SIGMA_A.tolist()}
sigma_s = {SIGMA_S.tolist()}
eta = 1.0
mm_per_unit = {MM_PER_UNIT}
intensity = {intensity}
light = {{ position = {list(light)}, intensity = [{INTENSITY}, {INTENSITY}, {INTENSITY}] }}

[output]
exr = "image.exr"
background = [0.0, 0.0, 0.0]
"""
    toml = out_dir / f"{name}.toml"
    toml.write_text(scene)
    run_dir = out_dir / name
    start = time.time()
    subprocess.run(
        [cloth_vis, "render", str(toml), "--out", str(run_dir), "--force", "--quiet"],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    seconds = time.time() - start
    report = json.loads((run_dir / "run-report.json").read_text())
    stage = next(s for s in report["stages"] if s["stage"] == "translucency")
    return read_exr(run_dir / "image.exr"), seconds, stage


def metrics(ours, ref, mask, scale):
    yo, yr = luminance(ours[..., :3]), luminance(ref[..., :3])
    mean = yr[mask].mean()
    l1 = np.abs(yo - yr)[mask].mean() / mean
    rms = np.sqrt(((yo - yr) ** 2)[mask].mean()) / mean
    s = ssim_map(display(yo, scale), display(yr, scale))[mask].mean()
    return l1, rms, s


def false_colour(err):
    t = np.clip(err, 0, 1)
    return np.stack([np.clip(2 * t, 0, 1), np.clip(2 - 2 * t, 0, 1) * np.clip(2 * t, 0, 1), 1 - t], -1)


def main():
    cloth_vis, out_dir, data = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    quick = "--quick" in sys.argv
    out_dir.mkdir(parents=True, exist_ok=True)
    models = [("bunny", data / "meshes/bun_zipper.ply"), ("dragon", data / "meshes/dragon_vrip_res2.ply")]
    size, spp = 256, 256
    if quick:
        models = [("bunny-res3", data / "meshes/bun_zipper_res3.ply")]
        size, spp = 96, 32
    rows = []
    for name, mesh in models:
        bbox = mi.load_dict({"type": "ply", "filename": str(mesh)}).bbox()
        lo, hi = np.array(bbox.min), np.array(bbox.max)
        centre, radius = (lo + hi) / 2, np.linalg.norm(hi - lo) / 2
        fov = 30.0
        distance = radius / np.sin(np.radians(fov / 2)) * 1.05
        camera = {"eye": (centre + distance * np.array([0.0, 0.15, 1.0]) / np.linalg.norm([0.0, 0.15, 1.0])).tolist(),
                  "target": centre.tolist(), "fov_deg": fov}
        lights = {
            "back": (centre + radius * np.array([-0.8, 1.2, -2.5])).tolist(),
            "side": (centre + radius * np.array([2.5, 1.0, 0.3])).tolist(),
        }
        for light_name, light in lights.items():
            case = f"{name}-{light_name}"
            ref, ref_s = mitsuba_render(mesh, camera, light, size, spp)
            ours, ours_s, stage = ours_render(cloth_vis, mesh, camera, light, size, out_dir, case, 1.0)
            plain, _, _ = ours_render(cloth_vis, mesh, camera, light, size, out_dir, case + "-diffuse", 0.0)
            mask = (ours[..., 3] > 0.999) & (ref[..., 3] > 0.999)
            yr = luminance(ref[..., :3])
            scale = 1.0 / max(np.percentile(yr[mask], 99), 1e-12)
            m_ours = metrics(ours, ref, mask, scale)
            m_plain = metrics(plain, ref, mask, scale)
            # Eq. 12 has no absolute scale (A(d) is per mm², multiplied by no area): the one
            # factor k on the scattered term that best fits the reference (least squares).
            scattered = ours[..., :3] - plain[..., :3]
            ys, yd = luminance(scattered)[mask], luminance(plain[..., :3])[mask]
            k = max(float(np.dot(ys, yr[mask] - yd) / max(np.dot(ys, ys), 1e-30)), 0.0)
            fitted = plain.copy()
            fitted[..., :3] += k * scattered
            m_fit = metrics(fitted, ref, mask, scale)
            rows.append((case, mask.sum(), ref_s, ours_s, stage["millis"], m_ours, m_plain, m_fit, k))
            err = np.abs(luminance(ours[..., :3]) - yr) * scale * mask
            panels = [display(ours[..., :3], scale), display(fitted[..., :3], scale),
                      display(ref[..., :3], scale), display(plain[..., :3], scale), false_colour(err)]
            strip = (np.concatenate(panels, axis=1) * 255).astype(np.uint8)
            Image.fromarray(strip).save(out_dir / f"{case}.png")
    print(f"seed 004 translucency against Mitsuba 3 volpath ({'quick: ' if quick else ''}{size}² px, {spp} spp), "
          "skin1, η = 1 (index-matched boundary), point light")
    print("relative luminance error L1 / RMS (÷ the reference's mean) and SSIM over the covered pixels;")
    print("eq. 12 as written, with the best single factor k on its term, and plain diffuse (R_d)")
    print(f"{'case':<14}{'pixels':>7}{'mitsuba s':>10}{'ours s':>7}{'pass ms':>8}"
          f"{'L1 eq12':>8}{'L1 k':>7}{'L1 diff':>8}{'RMS eq12':>9}{'RMS k':>7}{'RMS diff':>9}"
          f"{'SSIM eq12':>10}{'SSIM k':>7}{'SSIM diff':>10}{'k':>8}")
    for case, n, ref_s, ours_s, ms, mo, mp, mf, k in rows:
        print(f"{case:<14}{n:>7}{ref_s:>10.1f}{ours_s:>7.2f}{ms:>8.1f}"
              f"{mo[0]:>8.3f}{mf[0]:>7.3f}{mp[0]:>8.3f}{mo[1]:>9.3f}{mf[1]:>7.3f}{mp[1]:>9.3f}"
              f"{mo[2]:>10.3f}{mf[2]:>7.3f}{mp[2]:>10.3f}{k:>8.3f}")
    print(f"pictures (eq. 12 | fitted k | Mitsuba | plain diffuse | |eq. 12 − Mitsuba|): {out_dir}/*.png")


if __name__ == "__main__":
    main()
