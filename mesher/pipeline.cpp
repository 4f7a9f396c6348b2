#include "mesher/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>

#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/progress.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/mesh/system_memory.hpp"

namespace hexfem {

namespace {
// |mesh - CAD| / CAD volume above which the user is warned.
constexpr double kVolumeErrorWarning = 0.02;
// Share of the hexes placed that the volume-gap stage may send back before the user is told.
constexpr double kGapUndoneWarning = 0.1;
// |mesh - CAD| / CAD volume above which the part is meshed again with a curvature bound.
constexpr double kVolumeErrorRetry = 0.05;
// How many times the curvature bound is doubled at most (16, 32, 64 elements per turn).
constexpr int kCurvatureRetries = 3;
// A failure at h above the bounding-box diagonal over this is put down to the size.
constexpr double kLargeSizeDivisor = 8;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
// How often the CAD faces under flat or inverted cells are meshed again, each time at half the
// size before (h/2, h/4).
constexpr int kLocalRefinements = 2;
// The least memory a mesh takes per estimated interior point (V / h^3): every shared model at
// 1.1-1.4M vertices peaked at 1.45-3.9 GB per million (validation/volume.md, session 40), ANC101
// at 2M at 1.41. A floor, so that only a run sure to run out is refused; ANC101 at 19.8M was
// killed by the system with 24.2 GB available (1.2 GB per million had let it start).
constexpr double kBytesPerVolumePoint = 1.35e3;

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// (V - V_CAD) / V_CAD of the solid farthest off its CAD volume, signed; NaN when there is no
// solid or one has no CAD volume. `volumes` holds {solid, volume} records (a mesh's or a surface
// check's); both the retries and the surface check judge a multi-solid part by it.
template <class Volumes, class CadVolumeOf>
double farthest_solid_error(const Volumes& volumes, CadVolumeOf cad_volume_of) {
  double worst = std::nan("");
  for (const auto& v : volumes) {
    const double cad = cad_volume_of(v.solid);
    if (!(cad > 0)) return std::nan("");
    const double e = (v.volume - cad) / cad;
    if (!(std::abs(e) <= std::abs(worst))) worst = e;
  }
  return worst;
}

// A report for a mesh made again: the CAD figures of the first one, nothing of its mesh.
MeshReport report_for_retry(const MeshReport& r) {
  MeshReport again;
  again.file_unit = r.file_unit;
  again.cad_volume = r.cad_volume;
  again.solid_cad_volumes = r.solid_cad_volumes;
  again.cad_seconds = r.cad_seconds;
  return again;
}

// The CAD faces of the boundary faces that touch a node of a flat or inverted cell, sorted.
std::vector<int> faces_under_bad_cells(const MixedMesh& mesh) {
  std::vector<char> bad_node(mesh.nodes.size(), 0);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    if (cell_is_inverted(mesh, c) || cell_is_degenerate(mesh, c))
      for (int i = 0; i < num_nodes(mesh.cell_kind[c]); ++i) bad_node[mesh.cell(c)[i]] = 1;
  std::vector<int> faces;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f) {
    bool touches = false;
    for (int i = 0; i < (mesh.bface_is_quad(f) ? 4 : 3); ++i)
      touches = touches || bad_node[mesh.bface(f)[i]];
    if (touches && mesh.bface_cad_face[f] >= 0) faces.push_back(mesh.bface_cad_face[f]);
  }
  sort_unique(faces);
  return faces;
}

// The volume mesh of a surface mesh made at the given options, checked valid; fills the report's
// mesh figures.
MixedMesh mesh_volume_checked(const SurfaceMesh& surface, const MeshOptions& options,
                              MeshReport& r) {
  show_progress("meshing volume (" + std::to_string(surface.mesh.nodes.size()) +
                " surface vertices)...");
  MixedMesh mesh = mesh_volume(surface, options.volume, &r.volume);
  end_progress();

  // What we emit is valid, or nothing is: an inverted or flat cell or an open boundary would
  // give wrong frequencies downstream without any sign of it.
  r.stats = r.volume.stats;
  const MeshStats& stats = r.stats;
  if (stats.inverted > 0 || stats.degenerate > 0 || !stats.watertight) {
    const std::string what = "the volume mesher produced an invalid mesh (" +
                             std::to_string(stats.inverted) + " inverted, " +
                             std::to_string(stats.degenerate) + " flat cells, " +
                             std::to_string(stats.open_boundary_edges) +
                             " open boundary edges); nothing written - try another --h";
    if (!stats.watertight) throw Error(what);
    throw LocalMeshError(what, faces_under_bad_cells(mesh), "flat or inverted cells");
  }
  r.mesh_volume = stats.volume;
  r.volume_error = r.cad_volume > 0 ? (r.mesh_volume - r.cad_volume) / r.cad_volume : 0;
  r.retry_error = r.volume_error;
  if (r.solid_cad_volumes.size() > 2) {
    const double worst = farthest_solid_error(stats.solid_volumes, [&](int solid) {
      return static_cast<std::size_t>(solid) < r.solid_cad_volumes.size()
                 ? r.solid_cad_volumes[solid]
                 : 0.0;
    });
    if (!std::isnan(worst)) r.retry_error = worst;
  }
  return mesh;
}

SurfaceMesh surface_once(const CadModel& cad, const MeshOptions& options, MeshReport& r) {
  show_progress("meshing surfaces...");
  return mesh_surface(cad, options.surface, &r.surface);
}

// Surface and volume mesh at the given options, checked valid; fills the report's mesh figures.
MixedMesh mesh_once(const CadModel& cad, const MeshOptions& options, MeshReport& r) {
  return mesh_volume_checked(surface_once(cad, options, r), options, r);
}

// (V - V_CAD) / V_CAD for the volume V inside the surface mesh a report's checks measured; for a
// part of several solids, of the solid farthest off (MeshReport::retry_error), or NaN without
// per_solid. NaN without checks. The tets fill exactly that volume, and the elements stay within
// max_total_gap of the tets' volume: the volume mesh's error is this one within that gap.
double surface_volume_error(const CadModel& cad, const SurfaceReport& surface, double cad_volume,
                            bool per_solid) {
  if (surface.checks.empty() || !(cad_volume > 0)) return std::nan("");
  if (cad.num_solids() == 1 && surface.checks.size() == 1)
    return (surface.checks.front().volume - cad_volume) / cad_volume;
  if (!per_solid) return std::nan("");  // faces between solids lie inside the part
  return farthest_solid_error(surface.checks, [&](int solid) { return cad.solid_volume(solid); });
}

// mesh_once; where its mesh has flat or inverted cells, or its surface mesh crosses itself, the
// CAD faces there are meshed again at h/2, then h/4, and the user is told which. 917_fusee at h
// = 28.7: a B-spline face meets its planar neighbour at a knife edge, and at h its chord
// triangle lies on the neighbour's two triangles, a pocket of zero thickness that TetGen fills
// with two flat tets. 40mm_capot at h = 14.6 with the order-2 curvature bound: triangles of
// face 6 cross faces 99 and 120.
// With `surface`: the first try meshes that surface (made at options, its report in r.surface).
MixedMesh mesh_once_or_refined(const CadModel& cad, const MeshOptions& options, MeshReport& r,
                               const SurfaceMesh* surface = nullptr) {
  try {
    return surface ? mesh_volume_checked(*surface, options, r) : mesh_once(cad, options, r);
  } catch (const LocalMeshError& bad) {
    if (bad.cad_faces.empty() || !options.surface.repair) throw;
    std::vector<int> faces = bad.cad_faces;
    const double h = options.surface.h;
    for (int level = 1; level <= kLocalRefinements; ++level) {
      MeshOptions finer = options;
      const double size = h / (1 << level);
      for (int f : faces) finer.surface.face_sizes.emplace_back(f, size);
      MeshReport again = report_for_retry(r);
      try {
        MixedMesh mesh = mesh_once(cad, finer, again);
        std::string list;
        for (int f : faces) list += (list.empty() ? "" : ", ") + std::to_string(f);
        char buf[160];
        std::snprintf(buf, sizeof buf, " meshed again at h/%d: at h = %g %s %s", 1 << level, h,
                      faces.size() > 1 ? "they had" : "it had", bad.what_defect.c_str());
        again.warnings.push_back((faces.size() > 1 ? "CAD faces " : "CAD face ") + list + buf);
        again.refined_faces = faces;
        r = std::move(again);
        return mesh;
      } catch (const LocalMeshError& worse) {
        // The faces of the defects left join the list.
        faces.insert(faces.end(), worse.cad_faces.begin(), worse.cad_faces.end());
        sort_unique(faces);
      } catch (const CadError&) {
        throw;
      } catch (const Error&) {
        break;
      }
    }
    throw;
  }
}

}  // namespace

std::string volume_warning(double volume_error, double h) {
  if (!(std::abs(volume_error) > kVolumeErrorWarning)) return "";
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "the mesh volume is %+.1f %% off the CAD volume: h = %g is coarse for this "
                "part's thin or curved features (a smaller --h or --curvature N helps)",
                100 * volume_error, h);
  return buf;
}

std::vector<SolidVolumeError> solid_volume_errors(const CadModel& cad,
                                                  const std::vector<SolidVolume>& mesh_volumes) {
  std::vector<SolidVolumeError> out;
  if (cad.num_solids() < 2) return out;
  for (const SolidVolume& m : mesh_volumes) {
    SolidVolumeError e;
    e.solid = m.solid;
    e.cad_volume = cad.solid_volume(m.solid);
    e.mesh_volume = m.volume;
    e.error = e.cad_volume > 0 ? (e.mesh_volume - e.cad_volume) / e.cad_volume : 0;
    out.push_back(e);
  }
  return out;
}

std::string solid_volume_warning(const std::vector<SolidVolumeError>& solids, double h) {
  std::vector<const SolidVolumeError*> off;
  for (const SolidVolumeError& s : solids)
    if (std::abs(s.error) > kVolumeErrorWarning) off.push_back(&s);
  if (off.empty()) return "";
  const SolidVolumeError* worst = *std::max_element(
      off.begin(), off.end(),
      [](const auto* a, const auto* b) { return std::abs(a->error) < std::abs(b->error); });
  std::string list;
  for (const SolidVolumeError* s : off)
    list += (list.empty() ? "" : ", ") + std::to_string(s->solid);
  const char* hint = "(a smaller --h, --curvature N or --size-at helps)";
  char buf[400];
  if (off.size() == 1)
    std::snprintf(buf, sizeof buf,
                  "solid %d's mesh volume is %+.1f %% off its CAD volume, and its mass as much: "
                  "h = %g is coarse for it %s",
                  worst->solid, 100 * worst->error, h, hint);
  else
    std::snprintf(buf, sizeof buf,
                  "solids %s have mesh volumes more than 2 %% off their CAD volumes (solid %d: "
                  "%+.1f %%), and their masses as much: h = %g is coarse for them %s",
                  list.c_str(), worst->solid, 100 * worst->error, h, hint);
  return buf;
}

SurfaceMesh mesh_surface_closest(const CadModel& cad, const SurfaceOptions& options,
                                 SurfaceReport& report, std::vector<std::string>& warnings) {
  SurfaceMesh best = mesh_surface(cad, options, &report);
  double off = surface_volume_error(cad, report, cad.volume(), true);
  const double first = off;
  int curvature = options.curvature;
  double earlier = 0;  // the attempts' seconds before the one kept
  bool retried = false;
  for (int attempt = 0;
       attempt < kCurvatureRetries && options.repair && std::abs(off) > kVolumeErrorRetry;
       ++attempt) {
    curvature = curvature > 0 ? 2 * curvature : 16;
    SurfaceOptions next = options;
    next.curvature = curvature;
    SurfaceReport again;
    SurfaceMesh mesh;
    try {
      mesh = mesh_surface(cad, next, &again);
    } catch (const Error&) {
      break;  // the finer sizes exceed a budget or fail: keep the closest mesh so far
    }
    const double o = surface_volume_error(cad, again, cad.volume(), true);
    const bool closer = std::abs(o) < std::abs(off);
    for (const auto& [stage, sec] : (closer ? report : again).stage_seconds) earlier += sec;
    if (!closer) break;
    best = std::move(mesh);
    report = std::move(again);
    off = o;
    retried = true;
  }
  if (earlier > 0) report.stage_seconds.emplace_back("other attempts", earlier);
  if (retried) {  // (mesh_surface's own retries, for a mesh that fails its checks, say nothing)
    char buf[300];
    std::snprintf(buf, sizeof buf,
                  "at h = %g %s %+.1f %% off %s CAD volume; meshed again with a curvature "
                  "bound of %d elements per turn",
                  options.h, cad.num_solids() > 1 ? "a solid's surface was" : "the surface was",
                  100 * first, cad.num_solids() > 1 ? "its" : "the", report.curvature_used);
    warnings.push_back(buf);
  }
  return best;
}

MixedMesh mesh_part(const CadModel& cad, const MeshOptions& options, MeshReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  const double h = options.surface.h;
  if (!(h > 0) || !std::isfinite(h))
    throw Error("mesh size h must be > 0 (got " + std::to_string(h) + ")");
  if (cad.num_solids() == 0) throw Error("the CAD file holds no solid to mesh");
  const double estimate = cad.volume() / (h * h * h);
  if (estimate > options.max_volume_points && !options.surface.force) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "h = %g would give about %.3g interior points (limit %.3g); use a larger h or "
                  "--force",
                  h, estimate, options.max_volume_points);
    throw Error(buf);
  }
  // A run that needs more memory than the machine has would be killed by the system after
  // minutes of work, without a word: refused now, on a floor of the memory it needs.
  const double need = kBytesPerVolumePoint * estimate;
  const double have =
      options.memory_limit_bytes > 0 ? options.memory_limit_bytes : available_memory_bytes();
  if (have > 0 && need > have && !options.surface.force) {
    char buf[300];
    std::snprintf(buf, sizeof buf,
                  "h = %g would need at least %.1f GB of memory (about %.3g interior points), "
                  "more than the %.1f GB available; use a larger h or --force",
                  h, need / 1e9, estimate, have / 1e9);
    throw Error(buf);
  }
  MeshReport local;
  MeshReport& r = report ? *report : local;
  r.file_unit = cad.file_unit();
  r.cad_volume = cad.volume();
  const bool per_solid = cad.num_solids() > 1;
  if (per_solid) {
    r.solid_cad_volumes.assign(static_cast<std::size_t>(cad.num_solids()) + 1, 0.0);
    for (int s = 1; s <= cad.num_solids(); ++s) r.solid_cad_volumes[s] = cad.solid_volume(s);
  }

  // At a size near the part's own (faces narrower than h, chords across whole holes) the
  // stages fail in their own terms (crossing boundaries, a self-intersecting surface); the user
  // must hear that the size is the cause.
  auto with_size_hint = [&](auto&& step) {
    try {
      step();
    } catch (const CadError&) {
      throw;
    } catch (const Error& e) {
      const double diag = cad.bbox().diagonal();
      if (!(h > diag / kLargeSizeDivisor)) throw;
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    " (--h %g is too large for this part, whose bounding-box diagonal is %.4g "
                    "mm: use a smaller --h)",
                    h, diag);
      throw Error(e.what() + std::string(buf));
    }
  };
  // A size much coarser than the part's curved features cuts so much volume off with its chords
  // (the tie rod at h = diagonal / 30: -18.7 %) that the mesh is not the part. Meshed again
  // with a curvature bound (16 elements per turn, or twice the user's), which refines the
  // curved faces only, doubled while the mesh stays past the bound and gets closer (Propeller
  // at h = diagonal / 30: -18.0 %, then -11.3 % at 16, -2.9 % at 32); the closest mesh is kept,
  // and the user is told.
  // The attempts kept, each closer to the CAD volume than the one before; the last is the mesh
  // returned. The tets fill the surface mesh exactly and the elements keep within max_total_gap
  // of the tets' volume, so a mesh's volume error is its surface's within `margin`. An attempt
  // whose surface alone shows that another will follow waits without its volume mesh, which
  // would be thrown away once a later attempt comes closer (the Propeller at diagonal / 60:
  // two of its three attempts, 5.4 of 12.7 s, were thrown away).
  struct Attempt {
    MeshOptions options;
    MeshReport report;
    std::optional<SurfaceMesh> waiting;  // its volume not meshed yet
    MixedMesh mesh;
  };
  const double margin = 2 * options.volume.max_total_gap + 1e-4;
  auto sure_to_retry = [&](double off) {
    return options.surface.repair && std::abs(off) > kVolumeErrorRetry + margin;
  };
  std::vector<Attempt> kept;
  kept.push_back({options, r, {}, {}});
  with_size_hint([&] {
    Attempt& a = kept.back();
    SurfaceMesh first = surface_once(cad, options, a.report);
    const double off = surface_volume_error(cad, a.report.surface, r.cad_volume, per_solid);
    if (sure_to_retry(off)) {
      a.report.retry_error = off;
      if (!per_solid) a.report.volume_error = off;
      a.waiting = std::move(first);
    } else {
      a.mesh = mesh_once_or_refined(cad, options, a.report, &first);
    }
  });
  // Meshes the last attempt's volume if it waits. A later attempt whose volume fails is dropped,
  // as the loop below drops one that fails at once; the first one's failure is the part's.
  // Returns false when an attempt was dropped.
  auto mesh_last = [&] {
    bool none_dropped = true;
    while (kept.back().waiting) {
      Attempt& a = kept.back();
      if (kept.size() == 1) {
        with_size_hint(
            [&] { a.mesh = mesh_once_or_refined(cad, a.options, a.report, &*a.waiting); });
        a.waiting.reset();
        break;
      }
      try {
        a.mesh = mesh_volume_checked(*a.waiting, a.options, a.report);
        a.waiting.reset();
      } catch (const Error&) {
        kept.pop_back();
        none_dropped = false;
      }
    }
    return none_dropped;
  };
  const double first_error = kept.front().report.retry_error;
  const bool several = cad.num_solids() > 1;
  // by_solid: the attempts are judged by the solid farthest off (retry_error), else by the whole
  // part (volume_error; the same for one solid).
  auto retry_finer = [&](const MeshOptions& base, int curvature, const char* how, bool by_solid) {
    auto err = [by_solid](const MeshReport& m) {
      return by_solid ? m.retry_error : m.volume_error;
    };
    for (int attempt = 0;
         attempt < kCurvatureRetries && std::abs(err(kept.back().report)) > kVolumeErrorRetry &&
         options.surface.repair;
         ++attempt) {
      Attempt next{base, report_for_retry(r), {}, {}};
      curvature = curvature > 0 ? 2 * curvature : 16;
      next.options.surface.curvature = curvature;
      SurfaceMesh surface;
      try {
        surface = surface_once(cad, next.options, next.report);
      } catch (const Error&) {
        break;  // the finer sizes exceed a budget or fail: keep the closest mesh so far
      }
      const double signed_off =
          surface_volume_error(cad, next.report.surface, r.cad_volume, by_solid);
      const double off = std::abs(signed_off);
      const double best = std::abs(err(kept.back().report));
      if (off - best > 2 * margin) break;  // no closer, whatever its volume mesh
      const bool closer = best - off > 2 * margin;
      if (closer && sure_to_retry(off)) {
        next.report.retry_error = signed_off;
        if (!per_solid) next.report.volume_error = signed_off;
        next.waiting = std::move(surface);
      } else {
        try {
          next.mesh = mesh_volume_checked(surface, next.options, next.report);
        } catch (const Error&) {
          break;
        }
        if (!closer && !mesh_last()) break;  // too close to call against a waiting attempt
        if (!(std::abs(err(next.report)) < std::abs(err(kept.back().report)))) break;
      }
      char buf[300];
      std::snprintf(buf, sizeof buf,
                    "at h = %g %s %+.1f %% off %s CAD volume; meshed again with a curvature "
                    "bound of %d elements per turn%s",
                    h, several ? "a solid's mesh was" : "the mesh was", 100 * first_error,
                    several ? "its" : "the", curvature, how);
      next.report.warnings.push_back(buf);  // its own warnings: earlier attempts' meshes are gone
      kept.push_back(std::move(next));
    }
    return curvature;
  };
  const int reached = retry_finer(options, options.surface.curvature, "", per_solid);
  // The order-2 default stops the curvature bound at h/2 (curvature_min_ratio); where that
  // floor keeps the mesh off (Propeller at h = diagonal / 20: -17.5 % at every bound, while no
  // bound at all gives -3.7 %), the bound goes on without it before the part is refused. That is
  // for the whole part: a small solid kept off by the floor gets its volume back from the
  // curved cells, and going past the floor for it gave AS1 glued at h = 16 339k DOF instead of
  // 87k.
  if (per_solid) mesh_last();  // a waiting attempt's whole-part volume is known once meshed
  if (std::abs(kept.back().report.volume_error) > kVolumeErrorRetry &&
      options.surface.curvature_min_ratio > 0) {
    MeshOptions unfloored = options;
    unfloored.surface.curvature_min_ratio = 0;
    retry_finer(unfloored, reached / 2, " (and no floor at h/2)", false);
  }
  mesh_last();
  r = std::move(kept.back().report);
  MixedMesh mesh = std::move(kept.back().mesh);
  mesh.length_unit = "mm";  // the CAD model's lengths are converted to millimetres on reading
  // Chords across thin or strongly curved features cut volume off at a coarse h: legitimate,
  // but a user expecting the part's mass must hear of it.
  if (const std::string w = volume_warning(r.volume_error, h); !w.empty()) r.warnings.push_back(w);
  r.solids = solid_volume_errors(cad, r.stats.solid_volumes);
  if (const std::string w = solid_volume_warning(r.solids, h); !w.empty()) r.warnings.push_back(w);
  // The volume-gap stage keeps the mesh within max_total_gap of the tets' volume by sending
  // elements back to tets. Where the hexes' bilinear faces on curved thin walls lose volume
  // everywhere a little (1385_Laufrad at h = 8: 3.4e-3), it sends back half the hexes and H_vol
  // falls from 78 to 41 %: a cliff between two sizes that the user must hear of, with the way out.
  const std::size_t hexes = r.stats.cells_per_kind[static_cast<int>(CellKind::Hex8)],
                    undone = r.volume.gap_undone[static_cast<int>(CellKind::Hex8)];
  if (undone > 0 && undone > kGapUndoneWarning * static_cast<double>(hexes + undone)) {
    char buf[400];
    const double keep = 1.25 * std::abs(r.volume.volume_gap_before);
    std::snprintf(buf, sizeof buf,
                  "%zu of %zu hexes went back to tets to keep the mesh volume within %.1e of the "
                  "tets' (their faces on curved or thin walls change it by %.1e); `hexfem mesh "
                  "--max-gap %.1e` keeps them (a mesh `hexfem modal` then reads)",
                  undone, hexes + undone, options.volume.max_total_gap,
                  std::abs(r.volume.volume_gap_before), keep);
    r.warnings.push_back(buf);
  }
  for (std::string& w : touching_lumps(cad)) r.warnings.push_back(std::move(w));
  r.total_seconds = seconds_since(t0) + r.cad_seconds;
  return mesh;
}

CadModel read_cad_to_mesh(const std::filesystem::path& path, const MeshOptions& options,
                          MeshReport& report) {
  const auto t0 = std::chrono::steady_clock::now();
  show_progress("reading " + path.filename().string() + "...");
  CadModel cad = CadModel::read(path, options.read);
  report.cad_seconds = seconds_since(t0);
  return cad;
}

MixedMesh mesh_file(const std::filesystem::path& path, const MeshOptions& options,
                    MeshReport* report) {
  MeshReport local;
  MeshReport& r = report ? *report : local;
  const CadModel cad = read_cad_to_mesh(path, options, r);
  return mesh_part(cad, options, &r);
}

}  // namespace hexfem
