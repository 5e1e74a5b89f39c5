#!/usr/bin/env python3
"""Writes fuzz/regressions/<target>/probe-*: the hostile inputs of issue #12, one file each.

Run once from the repository root; the files are committed. Fuzzer findings are added beside
them (`cargo xtask fuzz` copies each crash artifact into its target's folder).
"""
import base64, json, os, struct, zlib

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "regressions")

def put(target, name, data):
    d = os.path.join(root, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

# C1: a property-less face element with 2^40 rows.
put("ply", "probe-c1-propertyless-face", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
    "property float y\nproperty float z\nelement face 1099511627776\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
put("ply", "probe-huge-vertex-count", "ply\nformat binary_little_endian 1.0\nelement vertex 1099511627776\n"
    "property float x\nproperty float y\nproperty float z\nend_header\n")

# C2: .npy of 2^40 (and 2^26) empty frames, no data.
def npy(shape):
    d = "{'descr': '<f4', 'fortran_order': False, 'shape': %s, }\n" % shape
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(d)) + d.encode()
put("npy", "probe-c2-empty-frames", npy("(1099511627776, 0, 3)"))
put("npy", "probe-c2-empty-frames-2e26", npy("(67108864, 0, 3)"))

# C4/C5: sparse accessors without a buffer view, repeated instances, empty morph targets.
sparse = struct.pack("<I", 0) + struct.pack("<3f", 1, 1, 1)
uri = "data:application/octet-stream;base64," + base64.b64encode(sparse).decode()
def viewless(count, instances, targets):
    prim = {"attributes": {"POSITION": 0}}
    if targets:
        prim["targets"] = [{} for _ in range(targets)]
    return json.dumps({
        "asset": {"version": "2.0"}, "scenes": [{"nodes": [0] * instances}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim]}],
        "buffers": [{"byteLength": 16, "uri": uri}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 4},
                        {"buffer": 0, "byteOffset": 4, "byteLength": 12}],
        "accessors": [{"componentType": 5126, "count": count, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1],
                       "sparse": {"count": 1, "indices": {"bufferView": 0, "componentType": 5125},
                                  "values": {"bufferView": 1}}}]})
put("gltf", "probe-c4-viewless-accessor", viewless(3 << 24, 1, 0))
put("gltf", "probe-c5-6000-instances", viewless(300000, 6000, 0))
put("gltf", "probe-c5-400-empty-targets", viewless(1000000, 1, 400))
def with_uri(u):
    return json.dumps({
        "asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"byteLength": 36, "uri": u}], "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}]})
put("gltf", "probe-uri-etc-passwd", with_uri("/etc/passwd"))
put("gltf", "probe-uri-dev-zero", with_uri("/dev/zero"))
put("gltf", "probe-uri-dotdot", with_uri("../../../../etc/passwd"))
put("gltf", "probe-uri-bad-escape", with_uri("a%FF.bin"))
# A GLB header that claims a huge JSON chunk.
put("glb", "probe-truncated-glb", b"glTF\x02\x00\x00\x00\xff\x00\x00\x00")
put("glb", "probe-chunk-length", b"glTF" + struct.pack("<II", 2, 28) + struct.pack("<I", 0xFFFFFFF0) + b"JSON{}  ")

# .hdr headers that claim more than the file holds.
put("hdr", "probe-52-bytes-16k", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 16384\n")
put("hdr", "probe-huge-header", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4294967295 +X 4294967295\n")
put("exr", "probe-truncated-exr", b"\x76\x2f\x31\x01\x02\x00\x00\x00channels\x00chlist\x00")

# C3: a PNG whose header claims 8192 x 8192 (CRC valid), and one claiming 1024 x 1024.
def png(w, h):
    raw = b"\x00\x80\x80\x80"
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
put("btf_image", "probe-c3-8192-png", png(8192, 8192))
put("btf_image", "probe-c3-1024-png", png(1024, 1024))

# .cpca and .btfpca: a header and nothing behind it.
put("cpca", "probe-header-only", b"CPCA\x01\x00\x00\x00" + b"\xff" * 24)
put("btfpca", "probe-header-only", b"BTFPCA\x01\x00" + b"\xff" * 24)

# OBJ: a face with a huge index, frames of different sizes.
put("obj", "probe-huge-index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n")
put("obj_frames", "probe-mismatched-frames", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n#---\nv 0 0 0\nf 1 1 1\n")

# Scenes: values that ran for minutes, and a source outside the folder.
put("scene_toml", "probe-sky-16384", '[[object]]\nname = "c"\nsource = "synth:cloth"\n[environment]\n'
    'source = "synth:sky"\nprefilter_sigma_deg = 90\n[synth]\nsky_width = 16384\n')
put("scene_toml", "probe-huge-image", '[camera]\nwidth = 4294967295\nheight = 1\n')
