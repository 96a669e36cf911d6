// Tutorial case (doc/tutorial.md): a steel disk D150 x 20 mm shrunk onto a
// steel shaft D30 x 300 mm, disk centred at z = 100 mm (one third of the
// span). Units: metres. rotorfit reads the physical groups at the bottom:
// the bodies are physical volumes, the fit and the bearing faces physical
// surfaces.
SetFactory("OpenCASCADE");

// Element sizes [m]: h_fit on the fit surface, growing to h_max away from
// it. The .prm sets them ("Geometry parameters"); these defaults are the
// tutorial's, for 'gmsh tutorial_disk.geo' on its own.
DefineConstant[ h_fit = 8e-3, h_max = 14e-3 ];

r_shaft = 0.015;  length = 0.300;   // shaft radius and length
r_disk  = 0.075;  width  = 0.020;   // disk outer radius and axial width
z_disk  = 0.100;                    // axial position of the disk's mid-plane
tol     = 1e-6;                     // bounding-box slack for the selections

// Two solids: the shaft, and the disk as a ring (outer cylinder minus bore).
Cylinder(1) = {0, 0, 0, 0, 0, length, r_shaft};
Cylinder(2) = {0, 0, z_disk - width/2, 0, 0, width, r_disk};
Cylinder(3) = {0, 0, z_disk - width/2, 0, 0, width, r_shaft};
BooleanDifference(4) = { Volume{2}; Delete; }{ Volume{3}; Delete; };

// Fragmenting makes the two solids share the bore face, so the shaft and
// the disk are meshed conformingly there; rotorfit then duplicates the
// nodes of that face, one copy per body, and puts the contact pairs on
// them. (The interference itself is a number in the .prm: both bodies are
// drawn at the same nominal radius.)
BooleanFragments{ Volume{1, 4}; Delete; }{}

// Volumes after fragmenting: the shaft lies inside its own cylinder, the
// disk is everything else.
shaft() = Volume In BoundingBox{-r_shaft - tol, -r_shaft - tol, -tol,
                                r_shaft + tol, r_shaft + tol, length + tol};
disk() = Volume{:};
disk() -= shaft();

// The fit: of the disk's boundary faces, the one no wider than the shaft
// (the bore; the disk's side faces and rim reach out to r_disk).
fit() = {};
faces() = Abs(Boundary{ Volume{disk()}; });
For i In {0 : #faces() - 1}
  box() = BoundingBox Surface{faces(i)};
  If (box(3) - box(0) < 2*r_shaft + 10*tol)
    fit() += faces(i);
  EndIf
EndFor

// The shaft's end faces, where the bearings act.
end_left()  = Surface In BoundingBox{-r_shaft - tol, -r_shaft - tol, -tol,
                                     r_shaft + tol, r_shaft + tol, tol};
end_right() = Surface In BoundingBox{-r_shaft - tol, -r_shaft - tol, length - tol,
                                     r_shaft + tol, r_shaft + tol, length + tol};

// The names the .prm refers to: 'Physical volume' of each body, 'Shaft
// surface' and 'Hub surface' of the interface, 'Surface' of each bearing.
Physical Volume("shaft")          = {shaft()};
Physical Volume("disk")           = {disk()};
Physical Surface("fit")           = {fit()};
Physical Surface("bearing_left")  = {end_left()};
Physical Surface("bearing_right") = {end_right()};

// Mesh size: h_fit within half an element of the fit, growing linearly to
// h_max over three coarse elements; nothing else decides the size.
Field[1] = Distance;
Field[1].FacesList = {fit()};
Field[2] = Threshold;
Field[2].InField  = 1;
Field[2].SizeMin  = h_fit;
Field[2].SizeMax  = h_max;
Field[2].DistMin  = 0.5*h_fit;
Field[2].DistMax  = 0.5*h_fit + 3*h_max;
Background Field  = 2;
Mesh.MeshSizeMax  = h_max;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints    = 0;
Mesh.MeshSizeFromCurvature = 0;
// rotorfit uses quadratic (curved) tetrahedra: let gmsh untangle any
// curved element that would otherwise have a negative Jacobian.
Mesh.HighOrderOptimize = 1;
