// The surface mesher, stage by stage in the paper's order: size field, edge points, cross
// field, packing of parallelograms, triangulation. Faces are meshed in parallel (OpenMP).
//
// Takes: the CAD model and SurfaceOptions.
// Gives: the SurfaceMesh (triangles, per-node frames and sizes) and a SurfaceReport.
// Keeps: closed, outward-oriented triangulation per solid, or a one-line Error.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/surface_check.hpp"
#include "mesher/surface_mesh.hpp"

namespace hexfem {

struct SurfaceOptions {
  double h = 1.0;                  // target size, mm
  int curvature = 0;               // elements per 2*pi, 0 = off
  double curvature_min_ratio = 0;  // the curvature bound stops at h * this (SizeOptions)
  std::vector<std::pair<int, double>> vertex_sizes;  // (CAD vertex id, size)
  std::vector<std::pair<int, double>> face_sizes;    // (CAD face id, size)
  std::vector<std::pair<int, double>> edge_sizes;    // (CAD edge id, size)
  double k = 0.7;                                    // packing exclusion factor (paper: 0.7)
  // --align-opposite T: faces across a wall up to T sizes thick are packed from each other's
  // points (opposite_seeds; 0 = off). On by default since session 28: over the 23 shared models
  // at diagonal / 30, 45, 60 and 90 it raises the mean H_vol by 0.4-1.4 points and lowers NC,
  // one model loses more than a point (control arm at / 30, -1.1), thin walls gain up to 27
  // points (validation/volume.md, "Thin walls ... the default").
  double align_opposite = 2;
  // Each edge point's size is the spacing its edge got, not the field's (sizes_from_edge_spacing;
  // --no-edge-spacing-size turns it off). On by default since session 29: a cube whose side h
  // does not divide is still a grid, and with relax_points the shared models gain (volume.md,
  // "Relaxation and edge spacing by default").
  bool sizes_from_edge_spacing = true;
  bool force = false;  // allow more than max_points
  // Surface points estimated before the work (from h, then from the sizes the edges got): 1e6
  // surface points make tens of millions of volume vertices, past this machine's memory; a thin
  // wall refines its faces to its thickness (a 100 x 100 x 0.03 mm plate at h = 5: 3.6e6 points,
  // 272 s, 2.8 GB for the surface alone).
  double max_points = 1e6;
  // Mesh again with a curvature bound when the result fails check_solids (see mesh_surface).
  bool repair = true;
};

struct SurfaceReport {
  double estimated_points = 0;  // sum over faces of area / h^2
  std::size_t edge_points = 0;  // nodes on CAD edges and vertices
  std::size_t points = 0;       // all nodes
  std::size_t triangles = 0;
  std::size_t candidates = 0;  // packing candidates examined
  std::size_t flips = 0;       // 3D Delaunay flips
  std::size_t background_triangles = 0;
  std::vector<std::pair<std::string, double>> stage_seconds;
  TriangleQuality quality;
  // check_solids of the returned mesh (closed, oriented, no self-intersection per solid).
  std::vector<SolidCheck> checks;
  // The curvature bound of the mesh returned: options.curvature, or the one a repair used.
  int curvature_used = 0;
};

// Throws hexfem::Error (one line) on bad options or a face that cannot be meshed. The mesh
// is checked (report->checks); when a solid fails and options.repair is set, the part is
// meshed again with a curvature bound (8 then 16 elements per turn, or 2x and 4x the user's)
// and the first valid mesh, else the last one, is returned. Deterministic.
SurfaceMesh mesh_surface(const CadModel& cad, const SurfaceOptions& options,
                         SurfaceReport* report = nullptr);

// One line per CAD edge where two lumps of a solid touch (an edge bounding four or another even
// number of face sides): meshed as it is, but the joint is a line, which a user should know of.
std::vector<std::string> touching_lumps(const CadModel& cad);

// Surface points the options would give, from the areas (the check behind max_points).
double estimate_surface_points(const CadModel& cad, const SurfaceOptions& options);

}  // namespace hexfem
