// TS - test shaft assembly (doc/test_shaft.md): steel shaft D20 x 260 mm,
// aluminium sleeve D80/D20 x 40 mm centred at z = 130 mm, radial interference
// set in the .prm. Units: metres. The sleeve and the shaft are fragmented so
// that the fit surface is conforming; rotorfit duplicates its nodes per body.
SetFactory("OpenCASCADE");
// Element sizes: overridden from the .prm ("Geometry parameters").
DefineConstant[ h_fit = 4.0e-3, h_max = 8.0e-3 ];
R_s = 0.010; L = 0.260;  // shaft radius and length
R_h = 0.040; z0 = 0.110; z1 = 0.150;  // sleeve outer radius, axial extent
e = 1e-6;

Cylinder(1) = {0, 0, 0, 0, 0, L, R_s};
Cylinder(2) = {0, 0, z0, 0, 0, z1 - z0, R_h};
Cylinder(3) = {0, 0, z0, 0, 0, z1 - z0, R_s};
BooleanDifference(4) = { Volume{2}; Delete; }{ Volume{3}; Delete; };
BooleanFragments{ Volume{1, 4}; Delete; }{}

shaft() = Volume In BoundingBox{-R_s-e, -R_s-e, -e, R_s+e, R_s+e, L+e};
all() = Volume{:};
sleeve() = all();
sleeve() -= shaft();

// fit surface: the cylindrical face r = R_s, z0 <= z <= z1 (not the discs)
cand() = Surface In BoundingBox{-R_s-e, -R_s-e, z0-e, R_s+e, R_s+e, z1+e};
fit() = {};
For i In {0 : #cand()-1}
  bb() = BoundingBox Surface{cand(i)};
  If (bb(5) - bb(2) > 10*e)
    fit() += cand(i);
  EndIf
EndFor
left() = Surface In BoundingBox{-R_s-e, -R_s-e, -e, R_s+e, R_s+e, e};
right() = Surface In BoundingBox{-R_s-e, -R_s-e, L-e, R_s+e, R_s+e, L+e};

Physical Volume("shaft") = {shaft()};
Physical Volume("sleeve") = {sleeve()};
Physical Surface("fit") = {fit()};
Physical Surface("bearing_left") = {left()};
Physical Surface("bearing_right") = {right()};

// fine at the fit, coarse elsewhere
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
Mesh.HighOrderOptimize = 1;  // untangle curved P2 elements (no negative Jacobians)
