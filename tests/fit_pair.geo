// Verification geometry: solid shaft (radius R_s) inside a hub (R_s..R_h),
// both of the same axial length T, z in [0, T]. With u_z = 0 on every end face
// the 3D solution is the plane-strain Lame solution (doc/theory.md 10a(i)); with free
// faces and small T it approaches plane stress (doc/theory.md 10a(ii), 10b).
SetFactory("OpenCASCADE");
DefineConstant[ R_s = 0.010, R_h = 0.040, T = 0.010, h_fit = 3e-3, h_max = 6e-3 ];
e = 1e-5;
Cylinder(1) = {0, 0, 0, 0, 0, T, R_s};
Cylinder(2) = {0, 0, 0, 0, 0, T, R_h};
BooleanDifference(3) = { Volume{2}; Delete; }{ Volume{1}; };
DefineConstant[ conforming = 1 ];
If (conforming)  // 0: separately meshed bodies (no coincident nodes; failure test)
  BooleanFragments{ Volume{1, 3}; Delete; }{}
Else
  Rotate {{0, 0, 1}, {0, 0, 0}, 0.1} { Volume{3}; }  // moves the hub's seam
EndIf
shaft() = Volume In BoundingBox{-R_s-e, -R_s-e, -e, R_s+e, R_s+e, T+e};
all() = Volume{:};
hub() = all();
hub() -= shaft();
cand() = Surface In BoundingBox{-R_s-e, -R_s-e, -e, R_s+e, R_s+e, T+e};
fit() = {};
For i In {0 : #cand()-1}
  bb() = BoundingBox Surface{cand(i)};
  If (bb(5) - bb(2) > 10*e)
    fit() += cand(i);
  EndIf
EndFor
ends() = Surface In BoundingBox{-R_h-e, -R_h-e, -e, R_h+e, R_h+e, e};
ends() += Surface In BoundingBox{-R_h-e, -R_h-e, T-e, R_h+e, R_h+e, T+e};
Physical Volume("shaft") = {shaft()};
Physical Volume("hub") = {hub()};
Physical Surface("fit") = {fit()};
Physical Surface("ends") = {ends()};
Field[1] = Distance;
Field[1].FacesList = {fit()};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_fit;
Field[2].SizeMax = h_max;
Field[2].DistMin = 0.5*h_fit;
Field[2].DistMax = 0.5*h_fit + 3*h_max;
Background Field = 2;
Mesh.MeshSizeMax = h_max;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.HighOrderOptimize = 1;
