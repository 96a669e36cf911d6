// Overhung rotor (doc/bearings.md): a stepped steel shaft, D50 from z = 0 to
// 400 mm and D40 from 400 to 500 mm, with a steel disk D240/D40 x 30 mm
// shrunk on the thin end at z = 440..470 mm, beyond the right journal
// bearing. The journal bearings are bands of the shaft surface that the .prm
// places by axial position and width: the geometry marks no bearing surface.
// Units: metres. Disk and shaft are fragmented so that the fit surface is
// conforming; rotorfit duplicates its nodes per body.
SetFactory("OpenCASCADE");
DefineConstant[ h_fit = 8.0e-3, h_max = 16.0e-3 ];
R_1 = 0.025; L_1 = 0.400;          // journal section
R_2 = 0.020; L = 0.500;            // disk seat to the shaft end
R_d = 0.120; z0 = 0.440; z1 = 0.470;  // disk outer radius, axial extent
e = 1e-6;

Cylinder(1) = {0, 0, 0, 0, 0, L_1, R_1};
Cylinder(2) = {0, 0, L_1, 0, 0, L - L_1, R_2};
BooleanUnion(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Cylinder(4) = {0, 0, z0, 0, 0, z1 - z0, R_d};
Cylinder(5) = {0, 0, z0, 0, 0, z1 - z0, R_2};
BooleanDifference(6) = { Volume{4}; Delete; }{ Volume{5}; Delete; };
BooleanFragments{ Volume{3, 6}; Delete; }{}

shaft() = Volume In BoundingBox{-R_1-e, -R_1-e, -e, R_1+e, R_1+e, L+e};
all() = Volume{:};
disk() = all();
disk() -= shaft();

// fit surface: the cylindrical face r = R_2, z0 <= z <= z1 (not the discs)
cand() = Surface In BoundingBox{-R_2-e, -R_2-e, z0-e, R_2+e, R_2+e, z1+e};
fit() = {};
For i In {0 : #cand()-1}
  bb() = BoundingBox Surface{cand(i)};
  If (bb(5) - bb(2) > 10*e)
    fit() += cand(i);
  EndIf
EndFor

Physical Volume("shaft") = {shaft()};
Physical Volume("disk") = {disk()};
Physical Surface("fit") = {fit()};

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
