//! Nested octahedral light directions with spherical-Voronoi solid angles, and HDR environment maps sampled per direction (thesis §4.4.3, §4.4.5).
