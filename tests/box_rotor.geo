// Verification geometry: a rotor of rectangular section b x h (x by y), length L, z in
// [0, L], its centre shifted by dx along x; physical volume "rotor". Its second moments
// about the axis and its centroid are known in closed form (doc/theory.md 4.1):
// J_xx / V = b^2 / 12 + dx^2, J_yy / V = h^2 / 12, J_xy = 0, centroid dx off the axis.
SetFactory("OpenCASCADE");
DefineConstant[ b = 0.03, h_y = 0.02, L = 0.2, dx = 0.002, h = 0.01 ];
Box(1) = {dx - b / 2, -h_y / 2, 0, b, h_y, L};
Physical Volume("rotor") = {1};
Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = 0.5 * h;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
