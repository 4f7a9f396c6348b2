// The volume stages in the paper's order. Each stage takes the recombination state as the
// previous one left it and keeps its invariant (recombine_state.hpp); mesh_volume times them.
#include "mesher/volume_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>

#include "mesher/conformal.hpp"
#include "mesher/frame_field_3d.hpp"
#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/parallel.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/recombine_conformity.hpp"
#include "mesher/recombine_hex.hpp"
#include "mesher/recombine_prism_pyramid.hpp"
#include "mesher/recombine_select.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/tetrahedralize.hpp"
#include "mesher/volume_gap.hpp"
#include "mesher/volume_points.hpp"
#include "mesher/volume_slivers.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace hexfem {

namespace {

void check_options(const VolumeOptions& o) {
  if (!(o.min_quality >= 0 && o.min_quality <= 1))
    throw Error("min quality must be in [0, 1], got " + std::to_string(o.min_quality));
  if (!(o.max_volume_gap > 0)) throw Error("the element volume tolerance must be positive");
  if (!(o.max_total_gap > 0)) throw Error("the volume gap bound must be positive");
  if (o.nc_hex_gain < 1)
    throw Error("the NC gain of a hex undone must be at least 1, got " +
                std::to_string(o.nc_hex_gain));
}

RecombineLimits recombine_limits(const VolumeOptions& o) {
  RecombineLimits l;
  l.min_quality = o.min_quality;
  l.min_pyramid_quality = o.min_pyramid_quality;
  l.sliver_quality = o.flat_tet_quality;
  l.keep_tet_quality = o.keep_tet_quality;
  l.fill.max_volume_gap = o.max_volume_gap;
  l.fill.max_face_twist = o.max_face_twist;
  return l;
}

VolumePoints insert_points(const SurfaceMesh& surface, const FrameField3D& field,
                           const SolidLocator& locator, const VolumeOptions& o) {
  VolumePointsOptions po;
  po.k = o.k;
  po.random = o.random_points;
  po.seed = o.random_seed;
  po.jitter = o.jitter;
  po.inherit_frame = o.inherit_frame;
  po.smooth_frame = o.smooth_frame;
  po.coherent_first = o.coherent_first;
  po.coherent = o.coherent;
  po.relax_iterations = o.relax_points;
  po.lpcvt.iterations = o.lp_cvt;
  po.lpcvt.p = o.lp_cvt_p;
  return insert_volume_points(surface, field, locator, po);
}

// Paper: hexes first, best quality first, under the conformity rules; the index stays for the
// prisms.
void place_hexes(RecombineState& s, ConformityIndex& index, HexSelection selection,
                 StageTimer& timer, VolumeReport& r) {
  index.reserve(s.used.size() / 6);  // at most one hex per six tets, about
  HexOptions ho;
  ho.min_quality = s.limits.min_quality;
  ho.fill = s.limits.fill;
  r.hex_candidates = 0;
  if (selection == HexSelection::kGreedy) {
    place_hexes_greedily(s, ho, index, &r.hex_candidates);
    r.stages.push_back(timer.lap("hexes"));
    return;
  }
  // The swaps' pool: the candidates the greedy pass enumerated at or above the swaps' quality
  // floor that hold a tet it left free. Each hex a 1-for-k swap puts in holds one: it overlaps
  // only the hex taken out, and k >= 2 hexes have more tets than that one. The greedy pass's
  // bands after the first search only around free tets (kSwap's pool). Searching every band in
  // full gives ANC101 h = 4.5 H_nbr 80.01 against 78.84 %, H_vol / 60 +0.66, but 1M vertices in
  // 84.9 s against 46 s; kSwapWide searches around the free tets instead (46 s;
  // validation/volume.md).
  const SwapOptions so;
  SortedRuns<HexCorners> found;
  place_hexes_greedily(s, ho, index, &r.hex_candidates, &found, static_cast<float>(so.min_quality));
  r.stages.push_back(timer.lap("hexes"));
  std::vector<Candidate> pool = hexes_holding_free_tets(s.topo, ho, found, s.used);
  found = {};
  if (selection == HexSelection::kSwapWide) {
    // Below the first band (searched in full), the bands again around the hexes next to a free
    // tet (wide_swap_search_mask). The greedy pass's later bands found some of them too.
    const float first =
        ho.quality_bands.empty() ? static_cast<float>(so.min_quality) : ho.quality_bands.front();
    const std::vector<Candidate> more =
        hexes_holding_free_tets(s.topo, ho, QualityBand{static_cast<float>(so.min_quality), first},
                                wide_swap_search_mask(s), s.used);
    std::vector<Candidate> both;
    both.reserve(pool.size() + more.size());
    std::set_union(pool.begin(), pool.end(), more.begin(), more.end(), std::back_inserter(both));
    pool = std::move(both);
  }
  r.stages.push_back(timer.lap("swap pool"));
  r.hex_swaps = improve_by_swaps(s, pool, so);
  // The index has no removal: rebuilt from the elements kept and put in.
  index = ConformityIndex{};
  index.reserve(s.used.size() / 6);
  for (const Candidate& e : s.elements) index.add(e);
  r.stages.push_back(timer.lap("hex swaps"));
}

// Then prisms from the free tets, and the slivers between two elements' faces or under a
// boundary quad.
void place_prisms(RecombineState& s, ConformityIndex& index, const VolumeOptions& o,
                  VolumeReport& r) {
  if (!o.no_prisms) {
    std::vector<Candidate> cands = enumerate_prisms(s);
    r.prism_candidates = cands.size();
    place_greedily(s, cands, index);
  }
  absorb_face_slivers(s, s.elements, SliverPolicy::kSharedOrBoundary);
}

// Pyramids on the unshared quad faces; flat slivers on quad faces go into their element, others
// into pyramids with two tets around them. A sliver still boxed in by pyramids: they go back to
// tets, and the sliver tries again.
void place_pyramids_and_slivers(RecombineState& s, const VolumeOptions& o, VolumeReport& r) {
  if (!o.no_pyramids) {
    std::vector<Candidate> cands = enumerate_pyramids(s);
    r.pyramid_candidates = cands.size();
    place_pyramids(s, cands);
  }
  absorb_face_slivers(s, s.elements, SliverPolicy::kFlat);
  if (o.no_pyramids) return;
  merge_slivers_into_pyramids(s);
  r.dissolved_pyramids = dissolve_pyramids_next_to_slivers(s);
  if (!r.dissolved_pyramids) return;
  release_orphan_slivers(s);
  absorb_face_slivers(s, s.elements, SliverPolicy::kFlat);
  merge_slivers_into_pyramids(s);
}

void repair_nc(RecombineState& s, const VolumeOptions& o, VolumeReport& r) {
  NcRepairOptions no;
  no.min_hex_gain = o.nc_hex_gain;
  no.make_pyramids = !o.no_pyramids;
  no.make_prisms = !o.no_prisms;
  const NcRepair nr = undo_nonconformal_elements(s, no);
  r.nc_faces_before_repair = nr.nc_before;
  r.nc_faces_after_repair = nr.nc_after;
  r.nc_repair_pyramids = nr.pyramids_added;
  r.nc_repair_prisms = nr.prisms_added;
  for (int k = 0; k < kNumCellKinds; ++k) r.nc_undone[k] = nr.undone[k];
}

// Cells and boundary faces (two surface triangles under a hex/prism quad become that quad, with
// the CAD face they share).
MixedMesh assemble(const SurfaceMesh& surface, const RecombineState& s, const SliverFlips& flips) {
  const TetTopology& topo = s.topo;
  const std::vector<Candidate>& elements = s.elements;
  const std::vector<char>& used = s.used;
  const TetMesh& tm = topo.mesh();
  const MixedMesh& sm = surface.mesh;
  MixedMesh mesh;
  mesh.nodes = tm.nodes;
  mesh.physical_names = sm.physical_names;
  for (const Candidate& e : elements)
    mesh.add_cell(e.kind, e.nodes.data(), tm.tet_solid[e.tets[0]]);
  for (std::size_t t = 0; t < tm.tets.size(); ++t)
    if (!used[t]) mesh.add_cell(CellKind::Tet4, tm.tets[t].data(), tm.tet_solid[t]);
  for (std::size_t t = 0; t < flips.added.size(); ++t)
    mesh.add_cell(CellKind::Tet4, flips.added[t].data(), flips.added_solid[t]);
  // Surface triangle -> the boundary quad (element, local face) covering it. The quad faces on
  // the surface are found on all threads and filed in element order (where two faces claim a
  // triangle, the later one keeps it).
  struct OnSurface {
    std::int32_t element, face, t1, t2;
  };
  const std::vector<OnSurface> found =
      parallel_collect<OnSurface>(elements.size(), [&](std::size_t i, std::vector<OnSurface>& out) {
        const Candidate& e = elements[i];
        const CellFaces& cf = faces_of(e.kind);
        for (int f = 0; f < cf.count; ++f) {
          if (cf.face[f].n != 4) continue;
          const QuadKey q = quad_corners(e, f);
          // A face with an interior corner is not on the surface (most of them).
          const auto ns = static_cast<std::int32_t>(topo.num_surface_nodes());
          if (q[0] >= ns || q[1] >= ns || q[2] >= ns || q[3] >= ns) continue;
          // The surface triangles under the face: split like the element's tets, or along the
          // other diagonal when a flat sliver between the two was absorbed into the element.
          std::int32_t t1 = -1, t2 = -1;
          for (int d : {quad_diagonal(topo, e, f), 1 - quad_diagonal(topo, e, f)}) {
            t1 = d == 0 ? topo.surface_triangle(q[0], q[1], q[2])
                        : topo.surface_triangle(q[0], q[1], q[3]);
            t2 = d == 0 ? topo.surface_triangle(q[0], q[2], q[3])
                        : topo.surface_triangle(q[1], q[2], q[3]);
            if (t1 >= 0 && t2 >= 0) break;
          }
          // A face over two (coplanar) CAD faces stays two triangles, each with its own CAD
          // face.
          if (t1 < 0 || t2 < 0 || topo.cad_face(t1) != topo.cad_face(t2)) continue;
          out.push_back({static_cast<std::int32_t>(i), f, t1, t2});
        }
      });
  std::vector<std::array<std::int32_t, 2>> quad_of(sm.num_bfaces(), {-1, -1});
  for (const OnSurface& o : found) quad_of[o.t1] = quad_of[o.t2] = {o.element, o.face};
  std::vector<char> emitted(elements.size() * 6, 0);
  for (std::size_t t = 0; t < sm.num_bfaces(); ++t) {
    const auto [e, f] = quad_of[t];
    if (e < 0) {
      mesh.add_bface(sm.bface(t)[0], sm.bface(t)[1], sm.bface(t)[2], -1, sm.bface_cad_face[t],
                     sm.bface_physical.empty() ? 0 : sm.bface_physical[t]);
      continue;
    }
    if (emitted[6 * e + f]) continue;
    emitted[6 * e + f] = 1;
    const LocalFace lf = faces_of(elements[e].kind).face[f];
    const auto& n = elements[e].nodes;
    mesh.add_bface(n[lf.v[0]], n[lf.v[1]], n[lf.v[2]], n[lf.v[3]], sm.bface_cad_face[t],
                   sm.bface_physical.empty() ? 0 : sm.bface_physical[t]);
  }
  return mesh;
}

// The report's counts and volumes, from the state and the statistics of the emitted mesh.
void fill_report(const RecombineState& s, const MixedMesh& mesh,
                 const std::vector<CellFaceRef>& faces, VolumeReport& r) {
  r.absorbed_slivers = s.absorbed.size();
  r.tets_in_elements = 0;
  r.volume_tets = r.volume_elements_gap = r.volume_absorbed = 0;
  r.boundary_quads = r.boundary_triangles = 0;
  for (const Candidate& e : s.elements)
    for (std::int32_t t : e.tets) r.tets_in_elements += t >= 0;
  for (std::size_t t = 0; t < s.used.size(); ++t) r.volume_tets += s.topo.tet_volume(t);
  // Where the gap comes from: each element against its own tets, and the absorbed slivers.
  r.volume_elements_gap = volume_gap(s.topo, s.elements, {});
  for (std::int32_t t : s.absorbed) r.volume_absorbed += s.topo.tet_volume(t);
  r.stats = compute_stats(mesh, faces);
  r.volume_rel_gap =
      r.volume_tets > 0 ? std::abs(r.stats.volume - r.volume_tets) / r.volume_tets : 0;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f)
    ++(mesh.bface_is_quad(f) ? r.boundary_quads : r.boundary_triangles);
}

// The tail of the pipeline: sliver flips, the check that each tet is in one place, assembly,
// NC flags, the lift of the slivers left, and the report's figures.
MixedMesh finish_mesh(RecombineState& s, const SurfaceMesh& surface, const VolumeOptions& options,
                      StageTimer& timer, VolumeReport& r) {
  const SliverFlips flips = flip_slivers(s);
  r.sliver_flips = flips.flips;
  r.flipped_tets = flips.removed.size();
  r.tets_from_flips = flips.added.size();
  r.slivers_left = flips.slivers_left;
  r.stages.push_back(timer.lap("sliver flips"));

  // Each TetGen tet in exactly one place, or the mesh would overlap or drop volume.
  s.verify(flips.removed);
  MixedMesh mesh = assemble(surface, s, flips);
  // The cell faces, sorted once for the NC flags and the statistics (moving vertices below keeps
  // them).
  std::vector<CellFaceRef> faces = sorted_cell_faces(mesh);
  flag_nonconformal_quads(mesh, faces);
  r.lifted_cells = lift_slivers(mesh, s.topo.num_surface_nodes(), options.flat_tet_quality);
  r.stages.push_back(timer.lap("assembly + NC"));
  if (options.conformal) {
    ConformalOptions co;
    for (std::size_t t = 0; t < s.used.size(); ++t) co.target_volume += s.topo.tet_volume(t);
    co.max_gap = options.max_total_gap;
    r.conformal = make_conformal(mesh, co);
    faces = sorted_cell_faces(mesh);
    r.stages.push_back(timer.lap("conformal"));
  }

  fill_report(s, mesh, faces, r);
  r.stages.push_back(timer.lap("statistics"));
  return mesh;
}

// A fresh report for a run with these (checked) options.
void start_report(const VolumeOptions& options, VolumeReport& r) {
  r = VolumeReport{};
#ifdef _OPENMP
  r.threads = omp_get_max_threads();
#endif
  check_options(options);
}

// Tets to the mixed mesh: the recombination and the tail, on `timer`.
MixedMesh recombine_timed(TetMesh tets, const SurfaceMesh& surface_in, const VolumeOptions& options,
                          StageTimer& timer, VolumeReport& r) {
  // Flat tets on the surface go; the surface takes their other diagonal (on a face between two
  // glued solids, a flip of the tets around them instead).
  SurfaceMesh surface = surface_in;
  r.flat_boundary_tets = drop_flat_boundary_tets(tets, surface, options.flat_tet_quality);
  r.flat_boundary_tets += flip_flat_interface_tets(tets, surface, options.flat_tet_quality);
  const TetTopology topo(tets, surface);
  RecombineState s(topo, recombine_limits(options));
  r.stages.push_back(timer.lap("tet topology"));
  ConformityIndex index;
  place_hexes(s, index, options.hex_selection, timer, r);
  place_prisms(s, index, options, r);
  r.stages.push_back(timer.lap("prisms"));
  place_pyramids_and_slivers(s, options, r);
  r.stages.push_back(timer.lap("pyramids"));
  if (options.nc_repair) repair_nc(s, options, r);
  r.stages.push_back(timer.lap("nc repair"));
  const VolumeGap vg = limit_volume_gap(s, options.max_total_gap);
  r.volume_gap_before = vg.tets > 0 ? vg.gap_before / vg.tets : 0;
  for (int k = 0; k < kNumCellKinds; ++k) r.gap_undone[k] = vg.undone[k];
  r.stages.push_back(timer.lap("volume gap"));

  // Where the flips and the lift leave a flat cell (a sliver of four surface vertices boxed in by
  // elements the NC repair made), the elements holding its edges go back to tets and the tail
  // runs again from the same state: a local fallback, counted in the report. Meshes without a
  // flat cell never take it.
  const std::vector<Candidate> elements_before = s.elements;
  const std::vector<std::int32_t> absorbed_before = s.absorbed;
  const std::vector<char> used_before = s.used;
  MixedMesh mesh = finish_mesh(s, surface, options, timer, r);
  if (r.stats.degenerate > 0) {
    s.elements = elements_before;
    s.absorbed = absorbed_before;
    s.used = used_before;
    r.flat_fallback_undone = dissolve_pyramids_next_to_slivers(s);
    release_orphan_slivers(s);
    r.stages.push_back(timer.lap("flat-cell fallback"));
    mesh = finish_mesh(s, surface, options, timer, r);
  }
  return mesh;
}

// The whole volume pipeline once, with `extra` among the interior points.
MixedMesh mesh_volume_once(const SurfaceMesh& surface_in, const VolumeOptions& options,
                           const std::vector<Vec3>& extra, VolumeReport& r) {
  start_report(options, r);
  StageTimer timer;
  const FrameField3D field(surface_in);
  const SolidLocator locator(surface_in);
  r.stages.push_back(timer.lap("frame field + locator"));

  VolumePoints points = insert_points(surface_in, field, locator, options);
  points.points.insert(points.points.end(), extra.begin(), extra.end());
  r.surface_vertices = surface_in.mesh.nodes.size();
  r.interior_points = points.points.size();
  r.frontal_points = points.frontal_count;
  r.lp_cvt = points.lpcvt;
  r.stages.push_back(timer.lap("volume points"));

  TetMesh tets =
      tetrahedralize(surface_in, points.points, locator, options.tetgen_delaunay_recovery);
  r.steiner_points = tets.steiner_points;
  r.tetgen_seconds = tets.tetgen_seconds;
  r.tets = tets.tets.size();
  r.stages.push_back(timer.lap("tetgen"));

  MixedMesh mesh = recombine_timed(std::move(tets), surface_in, options, timer, r);
  r.total_seconds = timer.total_seconds();
  r.total_cpu_seconds = timer.total_cpu_seconds();
  return mesh;
}

}  // namespace

MixedMesh mesh_volume(const SurfaceMesh& surface_in, const VolumeOptions& options,
                      VolumeReport* report) {
  VolumeReport local;
  VolumeReport& r = report ? *report : local;
  MixedMesh mesh = mesh_volume_once(surface_in, options, {}, r);
  // A flat tet of four co-planar surface nodes that no flip or lift removes: the whole pipeline
  // again with a point beside each (points_beside_flat_tets), at most four times. A run with
  // more points may tetrahedralize co-spherical points elsewhere differently and leave a flat
  // tet there (NIST CTC 01 at h = 7.75: 1, then 3, then 2 flat tets, then none), so the points
  // accumulate. Meshes without a flat cell never take this.
  std::vector<Vec3> extra;
  double seconds = 0, cpu_seconds = 0;  // of the runs before the last
  for (int retry = 0; retry < 4 && r.stats.degenerate > 0; ++retry) {
    const std::vector<Vec3> more = points_beside_flat_tets(mesh, SolidLocator(surface_in));
    if (more.empty()) break;
    extra.insert(extra.end(), more.begin(), more.end());
    seconds += r.total_seconds;
    cpu_seconds += r.total_cpu_seconds;
    mesh = mesh_volume_once(surface_in, options, extra, r);
  }
  if (!extra.empty()) {
    r.flat_retry_points = extra.size();
    r.stages.push_back({"flat-tet retries (earlier runs)", seconds, cpu_seconds});
    r.total_seconds += seconds;
    r.total_cpu_seconds += cpu_seconds;
  }
  return mesh;
}

MixedMesh recombine_tets(TetMesh tets, const SurfaceMesh& surface, const VolumeOptions& options,
                         VolumeReport* report) {
  VolumeReport local;
  VolumeReport& r = report ? *report : local;
  start_report(options, r);
  StageTimer timer;
  r.surface_vertices = surface.mesh.nodes.size();
  r.interior_points = tets.nodes.size() - surface.mesh.nodes.size();
  r.tets = tets.tets.size();
  MixedMesh mesh = recombine_timed(std::move(tets), surface, options, timer, r);
  r.total_seconds = timer.total_seconds();
  r.total_cpu_seconds = timer.total_cpu_seconds();
  return mesh;
}

}  // namespace hexfem
