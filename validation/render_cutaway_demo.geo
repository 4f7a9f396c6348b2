// Small mixed mesh to try validation/render_cutaway.py without hexfem: a hex block, a prism
// block and tets on top (Gmsh adds pyramids on the quads under the tets).
//   gmsh validation/render_cutaway_demo.geo -3 -format msh22 -o /tmp/demo.msh
//   validation/render_cutaway.py /tmp/demo.msh /tmp/demo.png
lc = 0.15;
Point(1) = {0, 0, 0, lc}; Point(2) = {1, 0, 0, lc}; Point(3) = {1, 1, 0, lc}; Point(4) = {0, 1, 0, lc};
Point(5) = {2, 0, 0, lc}; Point(6) = {2, 1, 0, lc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {2, 5}; Line(6) = {5, 6}; Line(7) = {6, 3};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, -2}; Plane Surface(2) = {2};
Transfinite Curve{1, 2, 3, 4} = 8; Transfinite Surface{1}; Recombine Surface{1};
a[] = Extrude{0, 0, 1}{Surface{1}; Layers{7}; Recombine;};   // hexahedra
b[] = Extrude{0, 0, 1}{Surface{2}; Layers{7}; Recombine;};   // prisms
c[] = Extrude{0, 0, 0.8}{Surface{a[0], b[0]};};              // tets (+ pyramids on the quads)
