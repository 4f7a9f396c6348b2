// Lp-CVT optimisation of the interior points (Lévy and Liu 2010, "Lp Centroidal Voronoi
// Tessellation and its applications"; their ANC101 mesh is the one issue 16 measures against).
//
// Minimises F = sum_i integral over the Voronoi cell of point i of
//   sum_k ( f_ik . (y - x_i) / h_i )^p dy,
// f_i the point's frame, h_i its size, p even (8 as in the article). For large p a cell's
// energy is least when the cell is a cube aligned with the frame, so the minimiser is a
// lattice of cubes: the point set a hex recombination wants. Surface points stay where they
// are; the interior points move (L-BFGS, the Delaunay triangulation rebuilt at each
// evaluation). The cells of surface and interior points count. Instead of clipping the cells
// by the boundary (the article's restricted Voronoi diagram), ghost points outside the solid
// close the surface points' cells: one size out along the normal, a surface point's cell is
// then the cube a lattice would give it, and no interior point gains by pushing its cell's
// volume out of the counted cells.
//
// The gradient is exact for that F: each cell is cut into tets (x_i, three Voronoi vertices of
// a facet), whose integral of a p-th power of a linear function has a closed form, and the
// Voronoi vertices (circumcentres of Delaunay tets) are differentiated through their 3x3 system.
//
// Takes: all points (surface points, interior points, ghosts), a frame and a size per point.
// Gives: the interior points' new positions; the caller keeps only moves that stay valid.
#pragma once

#include <cstddef>
#include <vector>

#include "mesher/frame_field_3d.hpp"

namespace hexfem {

struct LpCvtOptions {
  int iterations = 0;  // L-BFGS iterations (0: none)
  int p = 8;           // the exponent, even
};

struct LpCvtReport {
  double energy_before = 0;
  double energy_after = 0;
  int iterations = 0;
  int evaluations = 0;
  std::size_t moves_kept = 0;  // interior points that took their new place (volume_points.cpp)
};

// all[0, ns): fixed surface points; all[ns, ns + ni): interior points, moved; the rest: ghosts.
// frame and size: for the first ns + ni points. Gives the ni interior points' new places.
std::vector<Vec3> optimize_lp_cvt(const std::vector<Vec3>& all, std::size_t ns, std::size_t ni,
                                  const std::vector<Frame>& frame, const std::vector<double>& size,
                                  const LpCvtOptions& options, LpCvtReport* report = nullptr);

// The energy and its gradient (one entry per interior point) at `all`; for the tests.
double lp_cvt_energy(const std::vector<Vec3>& all, std::size_t ns, std::size_t ni,
                     const std::vector<Frame>& frame, const std::vector<double>& size, int p,
                     std::vector<Vec3>* gradient);

}  // namespace hexfem
