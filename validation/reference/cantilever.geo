// Sanity check of the reference chain: 100 x 10 x 10 mm steel cantilever, clamped at x = 0.
// field-notes.md: f1 converges to about 833.3 Hz (C3D20R / C3D8I fine meshes).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 100, 10, 10};
