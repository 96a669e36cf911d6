// Verification geometry: one solid cylinder, radius R, length L, z in [0, L],
// physical volume "rotor", end faces "end_left" (z = 0) and "end_right"
// (z = L). Free-free bending against Timoshenko (doc/theory.md 10c), rigid rotor on
// two bearings and free spinning disk (doc/theory.md 10d/10e).
SetFactory("OpenCASCADE");
DefineConstant[ R = 0.02, L = 0.4, h = 8e-3 ];
e = 1e-6;
Cylinder(1) = {0, 0, 0, 0, 0, L, R};
Physical Volume("rotor") = {1};
Physical Surface("end_left") = Surface In BoundingBox{-R-e, -R-e, -e, R+e, R+e, e};
Physical Surface("end_right") = Surface In BoundingBox{-R-e, -R-e, L-e, R+e, R+e, L+e};
Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = 0.5 * h;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.HighOrderOptimize = 1;
