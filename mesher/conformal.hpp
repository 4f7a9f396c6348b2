// Conformal pass (--conformal): after assembly, every non-conformal quad face (a quad of a hex,
// prism or pyramid against two triangles) is made conformal with real elements only.
//
// Takes: an assembled mixed mesh with its NC flags (flag_nonconformal_quads).
// Gives: the same region filled by cells whose faces all match (NC 0), new interior nodes
// appended to `nodes`. On an NC quad (a, b, c, d) split by the diagonal (a, c) on the far side:
//  - the tets around the edge (a, c) on that side (its half shell) go; a pyramid on the quad and,
//    for each shell tet (a, c, u, w), the tets (a, u, w, s) and (c, u, w, s) fill the shell, with
//    s the shell's second vertex when the shell has two tets (the paper's pyramid: no new node),
//    else a new node s placed where the worst new cell is best (the hex is kept);
//  - where that cannot be done (a non-tet cell around the edge, no valid position for s), the
//    quad's own cell is split about a new node at its centre: a pyramid on each matched or
//    boundary quad, two tets on each NC quad (the far side's diagonal), a tet on each triangle.
// A flat tet on a quad's four corners (a sliver between its diagonals) is dropped first, as the
// recombination absorbs such slivers: the only volume change, the sliver's own.
// Keeps: the union of the cells (the region), the boundary faces, every matched face; no new
// cell with a min scaled Jacobian below ConformalOptions::min_quality.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct ConformalOptions {
  double min_quality = 1e-3;  // no new cell with a lower min scaled Jacobian
  // The tet mesh's volume (0: unknown) and the relative gap to it allowed: past it, the most
  // bulging boundary quads get two triangles (boundary_bulge.hpp).
  double target_volume = 0;
  double max_gap = 8e-4;
  // Only these NC quads (their corner ids, in any order); empty: every one. With a list, the
  // boundary passes (pyramids on two boundary triangles, bulging quads) are skipped: the order-2
  // raise uses it for the faces whose hanging node cannot be tied (part_modal.cpp).
  std::vector<std::array<std::int32_t, 4>> only_quads;
};

struct ConformalReport {
  std::size_t nc_before = 0, nc_after = 0;
  std::size_t pyramids = 0;        // pyramids on NC quads (one per quad made conformal here)
  std::size_t shell_pyramids = 0;  // of those, on a two-tet shell: no new node
  std::size_t flip_pyramids = 0;   // of those, on a larger shell refilled about a node of its own
  std::size_t grown_cavities = 0;  // of those, in the shell grown by one or two layers of tets
  std::size_t steiner_points = 0;  // new nodes (shell fills and cell splits)
  std::array<std::size_t, kNumCellKinds> cells_split{};  // quad cells split about their centre
  std::size_t split_with_tets_behind = 0;   // of those, together with the tets behind an NC quad
  std::size_t boundary_pyramids_split = 0;  // pyramids on two boundary triangles: two tets
  std::size_t boundary_cells_split = 0;     // other cells on them, split about a node
  std::size_t bulge_quads_split = 0;        // boundary quads given two triangles for the volume
  std::size_t bulge_quads_restored = 0;     // of those tried, left quads (no valid split)
  double gap_before_bulge = 0, gap_after_bulge = 0;  // enclosed volume vs target, relative
  std::size_t absorbed_slivers = 0;  // flat tets on a quad's four corners, dropped (a tiny volume)
  std::size_t failed = 0;            // NC quads left (none unless every way failed)
  double hex_volume_before = 0, hex_volume_after = 0, volume = 0;
};

// Makes `mesh` conformal in place (see above); refreshes its NC flags.
ConformalReport make_conformal(MixedMesh& mesh, const ConformalOptions& options = {});

}  // namespace hexfem
