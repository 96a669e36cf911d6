// BI - bladed impeller assembly (doc/bladed_impeller.md): CI's shaft and hub
// (prm/conical_impeller.geo) with n_blades straight radial blades of
// thickness t_blade on the hub's cone. Units: metres, spin axis z.
// Hub profile (r, z) in mm: (30,560) (150,560) (150,575) (45,660) (30,660).
// Blade meridian: between the cone (150,575) -> (45,660) and the shroud line
// (150,590) -> (95,660): outlet width 15 mm at r = 150 mm, inlet r = 45 .. 95 mm
// at z = 660 mm. Each blade is the plate |y'| <= t_blade/2 (y' across the blade)
// cut by that meridian revolved; n_blades = 0 gives CI's bladeless hub.
// Shaft, hub and blades are fragmented: the blades share their root faces
// with the hub (one body), the fit surface is conforming and rotorfit
// duplicates its nodes per body.
SetFactory("OpenCASCADE");
DefineConstant[ h_fit = 8.0e-3, h_max = 16.0e-3, h_blade = 5.0e-3,
                n_blades = 8, t_blade = 5.0e-3 ];
// fewer than 3 blades (or a fraction) make an unbalanced, laterally
// anisotropic rotor, outside what the scene and its doc claim
If (n_blades != Floor(n_blades) || n_blades < 0 || n_blades == 1 || n_blades == 2)
  Error("bladed_impeller.geo: n_blades = %g; give 0 (the bladeless hub) or a whole number >= 3", n_blades);
  Abort;
EndIf
If (t_blade <= 0)
  Error("bladed_impeller.geo: t_blade = %g m; the blade thickness must be positive", t_blade);
  Abort;
EndIf
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
hub() = Extrude {{0, 0, 1}, {0, 0, 0}, 2*Pi} { Surface{101}; };

parts() = {1, hub(1)};
If (n_blades > 0)
  // the blades' meridian shares the cone line 103 with the hub, so that the
  // blade roots lie exactly on the cone (no overlap, no slivers)
  Point(203) = {0.150, 0, 0.590};
  Point(204) = {0.095, 0, 0.660};
  Line(202) = {103, 203}; Line(203) = {203, 204}; Line(204) = {204, 104};
  Curve Loop(201) = {202, 203, 204, -103};
  Plane Surface(201) = {201};
  env() = Extrude {{0, 0, 1}, {0, 0, 0}, 2*Pi} { Surface{201}; };
  plates() = {};
  For k In {0 : n_blades - 1}
    Box(1000 + k) = {0.040, -t_blade/2, 0.550, 0.120, t_blade, 0.115};
    Rotate {{0, 0, 1}, {0, 0, 0}, 2*Pi*k/n_blades} { Volume{1000 + k}; }
    plates() += 1000 + k;
  EndFor
  parts() += BooleanIntersection{ Volume{plates()}; Delete; }{ Volume{env(1)}; Delete; };
EndIf
BooleanFragments{ Volume{parts()}; Delete; }{}

shaft() = Volume In BoundingBox{-R_s-e, -R_s-e, -e, R_s+e, R_s+e, L+e};
all() = Volume{:};
impeller() = all();
impeller() -= shaft();
// the blades: the impeller's volumes whose bounding box is off the axis
blade() = {};
For i In {0 : #impeller()-1}
  bb() = BoundingBox Volume{impeller(i)};
  If (Abs(bb(0) + bb(3)) > 1e-4 || Abs(bb(1) + bb(4)) > 1e-4)
    blade() += impeller(i);
  EndIf
EndFor

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
Field[5] = Min;
Field[5].FieldsList = {2};
If (#blade() > 0)
  // h_blade in the blades, on their faces and edges (the hub side of the
  // root faces included); gmsh grades into the hub
  bs() = Abs(Boundary{ Volume{blade()}; });
  bc() = Abs(Boundary{ Surface{bs()}; });
  Field[3] = MathEval;
  Field[3].F = Sprintf("%g", h_blade);
  Field[4] = Restrict;
  Field[4].InField = 3;
  Field[4].VolumesList = {blade()};
  Field[4].SurfacesList = {bs()};
  Field[4].CurvesList = {bc()};
  Field[5].FieldsList = {2, 4};
EndIf
Background Field = 5;
Mesh.MeshSizeMax = h_max;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.HighOrderOptimize = 1;  // untangle curved P2 elements (no negative Jacobians)
