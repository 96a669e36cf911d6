// CI - conical impeller assembly (doc/conical_impeller.md): steel shaft D60 x 800 mm,
// aluminium impeller hub (blades omitted), profile (r, z) in mm
// (30,560) (150,560) (150,575) (45,660) (30,660) revolved about z.
// Units: metres. Shaft and hub are fragmented so that the fit surface is
// conforming; rotorfit duplicates its nodes per body.
SetFactory("OpenCASCADE");
DefineConstant[ h_fit = 8.0e-3, h_max = 16.0e-3 ];
R_s = 0.030; L = 0.800;
e = 1e-6;

Cylinder(1) = {0, 0, 0, 0, 0, L, R_s};
Point(101) = {0.030, 0, 0.560};
Point(102) = {0.150, 0, 0.560};
Point(103) = {0.150, 0, 0.575};
Point(104) = {0.045, 0, 0.660};
Point(105) = {0.030, 0, 0.660};
Line(101) = {101, 102}; Line(102) = {102, 103}; Line(103) = {103, 104};
Line(104) = {104, 105}; Line(105) = {105, 101};
Curve Loop(101) = {101, 102, 103, 104, 105};
Plane Surface(101) = {101};
rev() = Extrude {{0, 0, 1}, {0, 0, 0}, 2*Pi} { Surface{101}; };
BooleanFragments{ Volume{1, rev(1)}; Delete; }{}

shaft() = Volume In BoundingBox{-R_s-e, -R_s-e, -e, R_s+e, R_s+e, L+e};
all() = Volume{:};
impeller() = all();
impeller() -= shaft();

cand() = Surface In BoundingBox{-R_s-e, -R_s-e, 0.560-e, R_s+e, R_s+e, 0.660+e};
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
Physical Volume("impeller") = {impeller()};
Physical Surface("fit") = {fit()};
Physical Surface("bearing_left") = {left()};
Physical Surface("bearing_right") = {right()};

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
