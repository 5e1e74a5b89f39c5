//! wgpu adapter selection that works on any machine (hardware or Mesa lavapipe), and headless offscreen targets read back to PNG and EXR.
