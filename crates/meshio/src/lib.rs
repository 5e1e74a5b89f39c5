//! Validated loading of static meshes (PLY, OBJ, glTF) and mesh animations (glTF skinning and morph targets, OBJ frame folders, .npy arrays).
