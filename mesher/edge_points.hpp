// Stage 2: points on the CAD edges, spaced by the size field. Every face bounded by an edge
// uses the same points, so the surface mesh is conforming along edges by construction.
//
// Takes: the CAD model and the size field.
// Gives: points on every CAD edge, shared by the faces the edge bounds.
// Keeps: edge points spaced by the size field; an edge's points are the only boundary of its faces.
#pragma once

#include <array>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/size_field.hpp"

namespace hexfem {

struct EdgePoints {
  // Boundary nodes: node v-1 is CAD vertex v, edge interior points follow. The vertices of a
  // micro edge (shorter than a fiftieth of the size) share one node; the other's node is unused.
  std::vector<Vec3> xyz;
  std::vector<double> size;    // size field at the node
  std::vector<int> node_edge;  // edge id of an interior edge point, 0 for a CAD vertex
  // Per edge (index e-1): parameters t of its points, first to last, and their node ids.
  // A degenerate edge has two points, both its vertex; a closed edge starts and ends at its
  // vertex.
  std::vector<std::vector<double>> t;
  std::vector<std::vector<int>> node;
};

// One face's boundary in its parameter plane: the edge points of its wires in wire order.
// A node can appear at several (u, v) (both sides of a seam, the whole line of a pole).
struct FaceBoundary {
  std::vector<Vec2> uv;
  std::vector<int> node;
  std::vector<int> coedge;       // index into cad.coedges(f) of the coedge the point is on
  std::vector<int> prev_coedge;  // at a coedge's first point: the coedge ending there, else -1
  std::vector<double> t;         // edge parameter of the point on its coedge
  std::vector<std::array<int, 2>> segments;  // pairs of point indices, along the wires
};

// Discretises every edge. Where the straight segments of a face's boundary would cross in its
// parameter plane (a coarse size on a tight curve), the edges involved are refined.
// Throws hexfem::Error when a face boundary cannot be made free of crossings.
EdgePoints discretise_edges(const CadModel& cad, const SizeField& size);

FaceBoundary face_boundary(const CadModel& cad, int f, const EdgePoints& points);

// Each edge point's size becomes the spacing of its edge there where that is smaller (the mean
// of its two segments; a vertex takes its shortest segment), on the edges whose faces' edges
// all got about the same spacing over size (within 5 %). An edge of length L gets a whole
// number of segments, so its spacing differs from the field's h where L / h is not near a whole
// number (a 1 mm cube at h = 0.4: 3 segments of 0.33). The faces and the volume then fill in at
// the edges' spacing instead of meeting it off step. Never larger: the volume takes the largest
// surface size where no smaller one reaches (FrameField3D), and one long segment would coarsen
// the whole interior (ANC101 h 4.5: 72k interior points -> 53k).
void sizes_from_edge_spacing(const CadModel& cad, EdgePoints& points);

// A corner of a face: a CAD vertex where two consecutive coedges of a wire meet.
struct FaceCorner {
  int vertex = 0;
  int in_coedge = 0, out_coedge = 0;  // indices into cad.coedges(f): arriving, leaving
  // Interior angle of the face at the corner, degrees in [0, 360), between the CAD edges'
  // directions leaving the vertex, measured in the tangent plane; NaN where the tangent plane
  // or a direction is undefined (a pole, a cone apex, a degenerate edge).
  double angle = 0;
};
std::vector<FaceCorner> face_corners(const CadModel& cad, int f);

// Pairs of segments of `b` that cross (indices into b.segments).
std::vector<std::array<int, 2>> crossing_segments(const FaceBoundary& b);

}  // namespace hexfem
