// Decodes every meshopt-compressed buffer view (EXT_ or KHR_meshopt_compression) of one .glb
// with meshoptimizer's own decoder (npm package `meshoptimizer`, its WebAssembly build) and
// prints one JSON line: [{"view": i, "bytes": base64 of count × byteStride decoded bytes}, …].
// The reference the workspace's safe-Rust filters and codec calls are compared with
// (test_data::meshopt_reference_decode).
const fs = require('fs');
const { MeshoptDecoder } = require('meshoptimizer');
(async () => {
  await MeshoptDecoder.ready;
  const glb = fs.readFileSync(process.argv[2]);
  const jsonLength = glb.readUInt32LE(12);
  const root = JSON.parse(glb.subarray(20, 20 + jsonLength).toString());
  const bin = glb.subarray(20 + jsonLength + 8);
  const out = [];
  root.bufferViews.forEach((view, i) => {
    const ext = (view.extensions || {});
    const e = ext.KHR_meshopt_compression || ext.EXT_meshopt_compression;
    if (!e) return;
    const source = new Uint8Array(bin.buffer, bin.byteOffset + (e.byteOffset || 0), e.byteLength);
    const target = new Uint8Array(e.count * e.byteStride);
    MeshoptDecoder.decodeGltfBuffer(target, e.count, e.byteStride, source, e.mode, e.filter);
    out.push({ view: i, bytes: Buffer.from(target).toString('base64') });
  });
  console.log(JSON.stringify(out));
})().catch((e) => { console.error(String(e)); process.exit(2); });
