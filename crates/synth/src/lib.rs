//! Procedural data for demos and tests: a cloth drape animation and HDR skies with a sun.
