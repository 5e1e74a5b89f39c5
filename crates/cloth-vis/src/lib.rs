//! cloth-vis facade: scene files, the effect graph that builds only the stages a scene asks for, file IO, the CLI and the demo.
