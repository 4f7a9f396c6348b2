#include "mesher/volume_pipeline.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <nlohmann/json.hpp>

#include "mesher/frame_field_3d.hpp"
#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/recombine_conformity.hpp"
#include "mesher/recombine_hex.hpp"
#include "mesher/recombine_prism_pyramid.hpp"
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

using Clock = std::chrono::steady_clock;

// A tet this flat (min scaled Jacobian) is worth undoing a prism or a hex for.
constexpr double kFlatTetQuality = 1e-3;

// CPU time of this process's threads and of its finished children (TetGen runs in one).
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  rusage ru{};
  getrusage(RUSAGE_CHILDREN, &ru);
  return ts.tv_sec + 1e-9 * ts.tv_nsec + ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec +
         ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
}

class StageTimer {
 public:
  explicit StageTimer(VolumeReport& r)
      : r_(r),
        start_(Clock::now()),
        last_(start_),
        cpu_start_(cpu_seconds()),
        cpu_last_(cpu_start_) {}
  void stage(const char* name) {
    const auto now = Clock::now();
    const double cpu = cpu_seconds();
    r_.stages.push_back(
        {name, std::chrono::duration<double>(now - last_).count(), cpu - cpu_last_});
    last_ = now;
    cpu_last_ = cpu;
  }
  void finish() {
    r_.total_seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    r_.total_cpu_seconds = cpu_seconds() - cpu_start_;
  }

 private:
  VolumeReport& r_;
  Clock::time_point start_, last_;
  double cpu_start_, cpu_last_;
};

// Cells and boundary faces (two surface triangles under a hex/prism quad become that quad, with
// the CAD face they share).
MixedMesh assemble(const SurfaceMesh& surface, const TetTopology& topo,
                   const std::vector<Candidate>& elements, const std::vector<char>& used,
                   const SliverFlips& flips) {
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
  // Surface triangle -> the boundary quad (element, local face) covering it.
  std::vector<std::array<std::int32_t, 2>> quad_of(sm.num_bfaces(), {-1, -1});
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const Candidate& e = elements[i];
    const CellFaces cf = faces_of(e.kind);
    for (int f = 0; f < cf.count; ++f) {
      const LocalFace& lf = cf.face[f];
      if (lf.n != 4) continue;
      const QuadKey q = quad_corners(e, f);
      // The surface triangles under the face: split like the element's tets, or along the other
      // diagonal when a flat sliver between the two was absorbed into the element.
      std::int32_t t1 = -1, t2 = -1;
      for (int d : {quad_diagonal(topo, e, f), 1 - quad_diagonal(topo, e, f)}) {
        t1 = d == 0 ? topo.surface_triangle(q[0], q[1], q[2])
                    : topo.surface_triangle(q[0], q[1], q[3]);
        t2 = d == 0 ? topo.surface_triangle(q[0], q[2], q[3])
                    : topo.surface_triangle(q[1], q[2], q[3]);
        if (t1 >= 0 && t2 >= 0) break;
      }
      // A face over two (coplanar) CAD faces stays two triangles, each with its own CAD face.
      if (t1 < 0 || t2 < 0 || topo.cad_face(t1) != topo.cad_face(t2)) continue;
      quad_of[t1] = quad_of[t2] = {static_cast<std::int32_t>(i), f};
    }
  }
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

// Every TetGen tet must end up in exactly one place: an element, an absorbed sliver, or a tet
// of its own (a free one). Anything else is a bug that would overlap or drop volume.
void check_each_tet_used_once(std::size_t num_tets, const std::vector<Candidate>& elements,
                              const std::vector<std::int32_t>& absorbed,
                              const std::vector<char>& used) {
  std::vector<std::uint8_t> count(num_tets, 0);
  for (const Candidate& e : elements)
    for (std::int32_t t : e.tets)
      if (t >= 0) ++count[t];
  for (std::int32_t t : absorbed) ++count[t];
  for (std::size_t t = 0; t < num_tets; ++t) {
    if (!used[t]) ++count[t];
    if (count[t] != 1)
      throw Error("volume mesher: tet " + std::to_string(t) + " is used " +
                  std::to_string(count[t]) + " times (internal error)");
  }
}

}  // namespace

MixedMesh mesh_volume(const SurfaceMesh& surface_in, const VolumeOptions& options,
                      VolumeReport* report) {
  VolumeReport local;
  VolumeReport& r = report ? *report : local;
  r = VolumeReport{};
#ifdef _OPENMP
  r.threads = omp_get_max_threads();
#endif
  if (!(options.min_quality >= 0 && options.min_quality <= 1))
    throw Error("min quality must be in [0, 1], got " + std::to_string(options.min_quality));
  if (!(options.max_volume_gap > 0)) throw Error("the element volume tolerance must be positive");
  if (!(options.max_total_gap > 0)) throw Error("the volume gap bound must be positive");
  if (options.nc_hex_gain < 1)
    throw Error("the NC gain of a hex undone must be at least 1, got " +
                std::to_string(options.nc_hex_gain));
  StageTimer timer(r);

  const FrameField3D field(surface_in);
  const SolidLocator locator(surface_in);
  timer.stage("frame field + locator");

  VolumePointsOptions po;
  po.k = options.k;
  po.random = options.random_points;
  po.seed = options.random_seed;
  po.jitter = options.jitter;
  po.inherit_frame = options.inherit_frame;
  const VolumePoints points = insert_volume_points(surface_in, field, locator, po);
  r.surface_vertices = surface_in.mesh.nodes.size();
  r.interior_points = points.points.size();
  r.frontal_points = points.frontal_count;
  timer.stage("volume points");

  TetMesh tets = tetrahedralize(surface_in, points.points, locator);
  r.steiner_points = tets.steiner_points;
  r.tets = tets.tets.size();
  timer.stage("tetgen");

  // Flat tets on the surface go; the surface takes their other diagonal.
  SurfaceMesh surface = surface_in;
  r.flat_boundary_tets = drop_flat_boundary_tets(tets, surface, options.flat_tet_quality);
  const TetTopology topo(tets, surface);
  std::vector<char> used(tets.tets.size(), 0);
  ConformityIndex index;
  index.reserve(tets.tets.size() / 6);  // at most one hex per six tets, about
  HexOptions ho;
  ho.min_quality = options.min_quality;
  ho.fill.max_volume_gap = options.max_volume_gap;
  ho.fill.max_face_twist = options.max_face_twist;
  std::vector<Candidate> cands = enumerate_hexes(topo, ho);
  r.hex_candidates = cands.size();
  std::vector<Candidate> elements = place_greedily(topo, cands, used, index, ho.fill);
  cands = {};
  timer.stage("hexes");

  if (!options.no_prisms) {
    PrismOptions pr;
    pr.min_quality = options.min_quality;
    pr.fill.max_volume_gap = options.max_volume_gap;
    pr.fill.max_face_twist = options.max_face_twist;
    std::vector<Candidate> pc = enumerate_prisms(topo, used, pr);
    r.prism_candidates = pc.size();
    const auto kept = place_greedily(topo, pc, used, index, pr.fill);
    elements.insert(elements.end(), kept.begin(), kept.end());
  }
  std::vector<std::int32_t> absorbed =
      absorb_face_slivers(topo, elements, used, SliverPolicy::kSharedOrBoundary);
  timer.stage("prisms");

  if (!options.no_pyramids) {
    std::vector<Candidate> yc =
        enumerate_pyramids(topo, elements, used, options.min_pyramid_quality);
    r.pyramid_candidates = yc.size();
    const auto kept = place_pyramids(yc, used);
    elements.insert(elements.end(), kept.begin(), kept.end());
  }
  {
    const auto flat =
        absorb_face_slivers(topo, elements, used, SliverPolicy::kFlat, options.flat_tet_quality);
    absorbed.insert(absorbed.end(), flat.begin(), flat.end());
  }
  r.absorbed_slivers = absorbed.size();
  if (!options.no_pyramids) {
    auto kept = merge_slivers_into_pyramids(topo, elements, used, options.flat_tet_quality,
                                            options.min_pyramid_quality);
    elements.insert(elements.end(), kept.begin(), kept.end());
    // A sliver still boxed in by pyramids: they go back to tets, and the sliver tries again.
    r.dissolved_pyramids = dissolve_pyramids_next_to_slivers(
        topo, elements, used, options.flat_tet_quality, kFlatTetQuality);
    if (r.dissolved_pyramids) {
      release_orphan_slivers(topo, elements, absorbed, used, options.flat_tet_quality);
      const auto flat =
          absorb_face_slivers(topo, elements, used, SliverPolicy::kFlat, options.flat_tet_quality);
      absorbed.insert(absorbed.end(), flat.begin(), flat.end());
      r.absorbed_slivers = absorbed.size();
      kept = merge_slivers_into_pyramids(topo, elements, used, options.flat_tet_quality,
                                         options.min_pyramid_quality);
      elements.insert(elements.end(), kept.begin(), kept.end());
    }
  }
  timer.stage("pyramids");

  if (options.nc_repair) {
    PrismOptions pr;  // the prism stage's rules, for prisms in gaps
    pr.min_quality = options.min_quality;
    pr.fill.max_volume_gap = options.max_volume_gap;
    pr.fill.max_face_twist = options.max_face_twist;
    const NcRepair nr = undo_nonconformal_elements(
        topo, elements, absorbed, used, options.flat_tet_quality, kFlatTetQuality,
        options.min_pyramid_quality, options.nc_hex_gain, !options.no_pyramids,
        options.no_prisms ? nullptr : &pr);
    r.nc_faces_before_repair = nr.nc_before;
    r.nc_faces_after_repair = nr.nc_after;
    r.nc_repair_pyramids = nr.pyramids_added;
    r.nc_repair_prisms = nr.prisms_added;
    for (int k = 0; k < kNumCellKinds; ++k) r.nc_undone[k] = nr.undone[k];
    r.absorbed_slivers = absorbed.size();
  }
  timer.stage("nc repair");

  {
    const VolumeGap vg = limit_volume_gap(topo, elements, absorbed, used, options.max_total_gap,
                                          options.flat_tet_quality, kFlatTetQuality);
    r.volume_gap_before = vg.tets > 0 ? vg.gap_before / vg.tets : 0;
    for (int k = 0; k < kNumCellKinds; ++k) r.gap_undone[k] = vg.undone[k];
    r.absorbed_slivers = absorbed.size();
  }
  timer.stage("volume gap");

  const SliverFlips flips = flip_slivers(topo, used, options.flat_tet_quality);
  r.sliver_flips = flips.flips;
  r.flipped_tets = flips.removed.size();
  r.tets_from_flips = flips.added.size();
  r.slivers_left = flips.slivers_left;
  timer.stage("sliver flips");

  for (const Candidate& e : elements)
    for (std::int32_t t : e.tets) r.tets_in_elements += t >= 0;
  {
    std::vector<std::int32_t> gone = absorbed;
    gone.insert(gone.end(), flips.removed.begin(), flips.removed.end());
    check_each_tet_used_once(tets.tets.size(), elements, gone, used);
  }
  MixedMesh mesh = assemble(surface, topo, elements, used, flips);
  // The cell faces, sorted once for the NC flags and the statistics (moving vertices below keeps
  // them).
  const std::vector<CellFaceRef> faces = sorted_cell_faces(mesh);
  flag_nonconformal_quads(mesh, faces);
  r.lifted_cells = lift_slivers(mesh, topo.num_surface_nodes(), options.flat_tet_quality);
  timer.stage("assembly + NC");

  for (std::size_t t = 0; t < tets.tets.size(); ++t) r.volume_tets += topo.tet_volume(t);
  // Where the gap comes from: each element against its own tets, and the absorbed slivers.
  for (const Candidate& e : elements) r.volume_elements_gap += element_gap(topo, e);
  for (std::int32_t t : absorbed) r.volume_absorbed += topo.tet_volume(t);
  r.stats = compute_stats(mesh, faces);
  const MeshStats& st = r.stats;
  r.vertices = st.num_nodes;
  r.cells = st.cells_per_kind;
  r.num_cells = st.num_cells;
  r.h_nbr = st.h_nbr;
  r.h_vol = st.h_vol;
  r.q_mean = st.q_mean;
  r.q_min = st.q_min;
  r.interior_quads = st.interior_quads;
  r.nc_quads = st.nonconformal_quads;
  r.nc_percent = st.nc_percent;
  r.inverted = st.inverted;
  r.volume_mixed = st.volume;
  r.volume_rel_gap =
      r.volume_tets > 0 ? std::abs(r.volume_mixed - r.volume_tets) / r.volume_tets : 0;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f)
    ++(mesh.bface_is_quad(f) ? r.boundary_quads : r.boundary_triangles);
  timer.stage("statistics");
  timer.finish();
  return mesh;
}

nlohmann::json volume_report_json(const VolumeReport& r) {
  nlohmann::json j;
  j["vertices"] = r.vertices;
  j["surface_vertices"] = r.surface_vertices;
  j["interior_points"] = r.interior_points;
  j["steiner_points"] = r.steiner_points;
  if (r.frontal_points) j["frontal_points"] = r.frontal_points;
  j["tets_from_tetgen"] = r.tets;
  j["absorbed_slivers"] = r.absorbed_slivers;
  j["tets_in_elements"] = r.tets_in_elements;
  j["flat_boundary_tets"] = r.flat_boundary_tets;
  j["dissolved_pyramids"] = r.dissolved_pyramids;
  j["sliver_flips"] = r.sliver_flips;
  j["flipped_tets"] = r.flipped_tets;
  j["tets_from_flips"] = r.tets_from_flips;
  j["slivers_left"] = r.slivers_left;
  j["lifted_cells"] = r.lifted_cells;
  nlohmann::json cells;
  for (int k = 0; k < kNumCellKinds; ++k) cells[kind_name(static_cast<CellKind>(k))] = r.cells[k];
  j["cells"] = cells;
  j["num_cells"] = r.num_cells;
  j["candidates"] = {{"hex8", r.hex_candidates},
                     {"wedge6", r.prism_candidates},
                     {"pyramid5", r.pyramid_candidates}};
  j["h_nbr_percent"] = r.h_nbr;
  j["h_vol_percent"] = r.h_vol;
  j["q_mean"] = r.q_mean;
  j["q_min"] = r.q_min;
  j["interior_quads"] = r.interior_quads;
  j["nc_quads"] = r.nc_quads;
  j["nc_percent"] = r.nc_percent;
  j["inverted"] = r.inverted;
  j["boundary_triangles"] = r.boundary_triangles;
  j["boundary_quads"] = r.boundary_quads;
  j["volume_tets"] = r.volume_tets;
  j["volume_mixed"] = r.volume_mixed;
  j["volume_rel_gap"] = r.volume_rel_gap;
  j["volume_elements_gap"] = r.volume_elements_gap;
  j["volume_absorbed"] = r.volume_absorbed;
  j["volume_gap_before_limit"] = r.volume_gap_before;
  nlohmann::json undone;
  for (int k = 0; k < kNumCellKinds; ++k)
    if (r.gap_undone[k]) undone[kind_name(static_cast<CellKind>(k))] = r.gap_undone[k];
  j["undone_for_volume_gap"] = undone.is_null() ? nlohmann::json::object() : undone;
  nlohmann::json nc_undone;
  for (int k = 0; k < kNumCellKinds; ++k)
    if (r.nc_undone[k]) nc_undone[kind_name(static_cast<CellKind>(k))] = r.nc_undone[k];
  j["nc_repair"] = {{"nc_faces_before", r.nc_faces_before_repair},
                    {"nc_faces_after", r.nc_faces_after_repair},
                    {"undone", nc_undone.is_null() ? nlohmann::json::object() : nc_undone},
                    {"pyramids_added", r.nc_repair_pyramids},
                    {"prisms_added", r.nc_repair_prisms}};
  nlohmann::json stages = nlohmann::json::array();
  for (const auto& s : r.stages)
    stages.push_back({{"stage", s.name}, {"seconds", s.seconds}, {"cpu_seconds", s.cpu_seconds}});
  j["stages"] = stages;
  j["total_seconds"] = r.total_seconds;
  j["total_cpu_seconds"] = r.total_cpu_seconds;
  j["threads"] = r.threads;
  return j;
}

std::string volume_report_text(const VolumeReport& r) {
  char buf[512];
  std::string s;
  auto line = [&](const char* fmt, auto... args) {
    std::snprintf(buf, sizeof buf, fmt, args...);
    s += buf;
    s += '\n';
  };
  line("vertices        %zu (surface %zu, interior %zu, steiner %zu)", r.vertices,
       r.surface_vertices, r.interior_points, r.steiner_points);
  line("tets (tetgen)   %zu (%zu flat slivers on quad faces absorbed)", r.tets, r.absorbed_slivers);
  line(
      "sliver flips    %zu (%zu tets -> %zu), %zu slivers left; %zu flat tets on the surface "
      "dropped",
      r.sliver_flips, r.flipped_tets, r.tets_from_flips, r.slivers_left, r.flat_boundary_tets);
  if (r.lifted_cells)
    line("lifted          %zu slivers by moving one interior vertex each", r.lifted_cells);
  line("elements        %zu: hex %zu, prism %zu, pyramid %zu, tet %zu", r.num_cells,
       r.cells[static_cast<int>(CellKind::Hex8)], r.cells[static_cast<int>(CellKind::Wedge6)],
       r.cells[static_cast<int>(CellKind::Pyramid5)], r.cells[static_cast<int>(CellKind::Tet4)]);
  line("H_nbr           %.2f %%", r.h_nbr);
  line("H_vol           %.2f %%", r.h_vol);
  line("Q (hex)         mean %.3f, min %.3f", r.q_mean, r.q_min);
  line("NC              %.2f %% (%zu of %zu interior quads)", r.nc_percent, r.nc_quads,
       r.interior_quads);
  line("inverted        %zu", r.inverted);
  line(
      "volume          tets %.9g, mixed %.9g, gap %.2e (elements - their tets %.4g, absorbed "
      "slivers %.4g)",
      r.volume_tets, r.volume_mixed, r.volume_rel_gap, r.volume_elements_gap, r.volume_absorbed);
  line("volume gap      %.2e before undoing %zu hex, %zu prism, %zu pyramid losing most",
       std::abs(r.volume_gap_before), r.gap_undone[static_cast<int>(CellKind::Hex8)],
       r.gap_undone[static_cast<int>(CellKind::Wedge6)],
       r.gap_undone[static_cast<int>(CellKind::Pyramid5)]);
  if (r.nc_faces_before_repair > 0)  // not with --no-nc-repair
    line(
        "nc repair       %zu -> %zu NC faces: undid %zu hex, %zu prism, %zu pyramid; made %zu "
        "pyramids, %zu prisms",
        r.nc_faces_before_repair, r.nc_faces_after_repair,
        r.nc_undone[static_cast<int>(CellKind::Hex8)],
        r.nc_undone[static_cast<int>(CellKind::Wedge6)],
        r.nc_undone[static_cast<int>(CellKind::Pyramid5)], r.nc_repair_pyramids,
        r.nc_repair_prisms);
  for (const auto& st : r.stages)
    line("time %-22s %8.3f s wall %8.3f s cpu", st.name.c_str(), st.seconds, st.cpu_seconds);
  line("time total                 %8.3f s wall %8.3f s cpu (%d threads)", r.total_seconds,
       r.total_cpu_seconds, r.threads);
  return s;
}

}  // namespace hexfem
