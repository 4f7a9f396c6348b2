// 3D frontal point insertion (paper, "Volume meshing: the 3D point insertion algorithm"):
// every surface vertex starts in a FIFO queue; each popped point proposes six neighbours at
// +-d*d_i along its frame (d the mean of the sizes at parent and candidate); a candidate is kept
// when it lies inside the solid, not within k*h of the boundary, and no point lies within k*h of
// it in the L-infinity distance oriented by its frame (eq. 7).
// A point's frame is the frame of the surface vertex its front started from (inherited from
// parent to child), not the paper's frame of the nearest surface vertex: each front then grows
// as one straight lattice up to where it meets another, instead of switching orientation where
// the nearest vertex changes (ANC101 h = 4.5: H_vol +1.1 points, H_nbr +2.0; validation/volume.md).
// With coherent_first (the pipeline's default) the fronts of box-like planar walls start first
// and the others when those have filled what they reach (see VolumePointsOptions).
// With smooth_frame (--smooth-frame, a study switch) a point's frame is instead the smooth
// field's at its position (frame_field_smooth.hpp): the fronts turn where walls of different
// orientations meet (ANC101 h = 4.5: H_nbr 65.96 -> 68.35 %, H_vol 87.82 -> 88.77 %), but the
// shared models at diagonal/30 lose on average (H_vol -0.34 points, tie_rod -10.2, cylinder
// -3.2: on revolved parts the straight lattices grown from the end faces make more hexes).
//
// Takes: the SurfaceMesh, the 3D frame field and the locator.
// Gives: the interior points (VolumePoints).
// Keeps: every point inside its solid, none within k h of the boundary or of another point.
#pragma once

#include <cstdint>
#include <vector>

#include "mesher/frame_field_3d.hpp"
#include "mesher/frame_field_smooth.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/surface_mesh.hpp"
#include "mesher/volume_points_lpcvt.hpp"

namespace hexfem {

// Which walls lead with coherent_first: frames whose walls face at least min_axes of their axes
// and hold at least min_share of the surface nodes. Three and 10 %: only the part's main frame
// leads (sessions 31-). Two and 1 % (--coherent-axes 2 --coherent-share 0.01, a study) let a
// block turned against the rest lead too, before the main lattice floods it from the base:
// ANC101 h = 4.5 without pyramids or NC repair H_nbr 76.84 -> 77.75 %; but pairs of flats on
// curved parts lead as well and flood them (control arm H_vol / 60 -4.6 points, mean / 30 and
// / 60 -0.33 and -0.22; validation/volume.md, session 34).
struct CoherentWalls {
  int min_axes = 3;
  double min_share = 0.1;
};

struct VolumePointsOptions {
  double k = 0.7;                // exclusion radius factor (paper: 0.7), in (0, 1)
  bool random = false;           // random points at the frontal density instead (for the study)
  std::uint64_t seed = 1;        // random mode only
  std::size_t random_count = 0;  // random mode: points wanted (0: as many as the frontal run)
  // Each point is finally moved by up to jitter*h in a direction drawn from its index. A
  // lattice of co-spherical points makes TetGen's exact predicates several times slower, but
  // jitter also breaks cubes into more slivers and costs hexes: off by default.
  double jitter = 0;
  // Frame of a point: the one its front started from (true), or the nearest surface vertex's
  // (false: the paper's rule). The size is always the nearest surface vertex's.
  bool inherit_frame = true;
  // Frame of a point: the smooth field's at its position (frame_field_smooth.hpp), built here
  // from the surface frames; overrides inherit_frame. Off by default (issue 16 study).
  bool smooth_frame = false;
  SmoothFrameOptions smooth;
  // Coherent walls first: the FIFO starts from the surface nodes of walls where the frame field
  // does not turn and whose common frame faces walls along all three of its axes (box-like walls,
  // 10 % of the surface nodes or more: volume_points.cpp, leading_nodes, CoherentWalls); the other
  // fronts (curved faces, around holes) start when it runs empty. One straight lattice then fills
  // what those walls reach, and the turning fronts only the layers left next to their faces (ANC101
  // h = 4.5: H_nbr 66.75 -> 77.04 %, H_vol 88.14 -> 92.73 %, NC 3.93 -> 2.21 %). The pipeline asks
  // for it (VolumeOptions::coherent_first).
  bool coherent_first = false;
  CoherentWalls coherent;
  // Jacobi sweeps of the lattice relaxation after the frontal insertion (0: none; the pipeline
  // asks for 30, VolumeOptions::relax_points).
  int relax_iterations = 0;
  // Lp-CVT optimisation of the interior points after the insertion (volume_points_lpcvt.hpp;
  // iterations 0: none; study).
  LpCvtOptions lpcvt;
};

struct VolumePoints {
  std::vector<Vec3> points;         // interior points, in insertion order
  std::vector<std::int32_t> solid;  // solid id of each point
  std::size_t candidates = 0;       // candidates examined
  std::size_t frontal_count = 0;    // random mode: the frontal run's count it aimed at
  LpCvtReport lpcvt;                // the Lp-CVT optimisation's energies, when it ran
};

VolumePoints insert_volume_points(const SurfaceMesh& surface, const FrameField3D& field,
                                  const SolidLocator& locator,
                                  const VolumePointsOptions& options = {});

}  // namespace hexfem
