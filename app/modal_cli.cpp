#include "app/modal_cli.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "app/cli_checks.hpp"
#include "app/part_modal.hpp"
#include "fem/boundary.hpp"
#include "fem/material.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/singular_edges.hpp"

namespace hexfem {

void add_modal_options(CLI::App& sub, ModalCliOptions& o) {
  sub.add_option("--fix", o.fix,
                 "fixed DOFs, repeatable: face:3,7 | group:NAME | \"x<0.001\" | "
                 "\"z<1e-3&x>9.99\"; append @xyz to fix only some components (coordinates in "
                 "the mesh's units)");
  sub.add_option("--material", o.materials,
                 "steel | aluminium | titanium (default steel); repeatable: solid:2,5=aluminium "
                 "or solid:3=E,nu,rho (SI) gives some solids of an assembly their own");
  o.E_given = sub.add_option("--E", o.E, "Young's modulus [Pa], overrides the material's");
  o.nu_given = sub.add_option("--nu", o.nu, "Poisson's ratio, overrides the material's");
  o.rho_given = sub.add_option("--rho", o.rho, "density [kg/m^3], overrides the material's");
  sub.add_option("--modes", o.modes, "number of modes (default " + std::to_string(o.modes) + ")");
  o.hex8_given = sub.add_option("--hex8", o.hex8,
                                "hex formulation: incompatible (default, bending-accurate) or full "
                                "(= CalculiX C3D8)");
  o.order_given = sub.add_option(
      "--order", o.order,
      "element order: 1 (hex8, wedge6, pyramid5, tet4) or 2 (hex20, wedge15, pyramid13, tet10; "
      "boundary nodes on the CAD geometry). Default: 2 for a CAD part, a mesh file's own order");
  sub.add_option("--solver", o.solver,
                 "direct (CHOLMOD), iterative (LOBPCG + GAMG; also under mpirun) or auto "
                 "(default: by DOF count and the estimated factor memory)");
  sub.add_flag("--conformal", o.conformal,
               "CAD input: a mesh with no NC face (each made conformal with a pyramid and tets)");
  sub.add_option("--size-at", o.size_at,
                 "CAD input: size at a CAD vertex, edge or face, repeatable: vertex:ID=S | "
                 "edge:ID=S | face:ID=S (S in mm, or 0.5h: a fraction of --h)");
  o.curvature_given = sub.add_option(
      "--curvature", o.curvature,
      "CAD input: curvature bound, N elements per 2*pi on curved edges and faces (0 = "
      "off). Default: " +
          std::to_string(kOrder2Curvature) +
          " at order 2 (never finer than h/2 from it), off at order 1");
  sub.add_option(
         "--relax-points", o.relax_points,
         "CAD input: sweeps moving each interior point towards its lattice neighbours "
         "(default 0 here, 30 on `mesh`: the relaxed points cost order-2 accuracy on curved parts)")
      ->check(CLI::Range(0, 1000));
  sub.add_flag("--coherent-first", o.coherent_first,
               "CAD input: the fronts of box-like planar walls start first (default off here, "
               "on for `mesh`: it cost order-2 accuracy on the steel part)");
  sub.add_option("--align-opposite", o.align_opposite,
                 "CAD input: pack the two faces of a wall up to T sizes thick from the same points "
                 "(default 2, 0 = off; as on `mesh`)")
      ->check(CLI::Range(0.0, 10.0));
  sub.add_flag("--glue", o.glue, std::string("CAD input: ") + kGlueHelp);
  o.singular_size_given = sub.add_option(
      "--singular-size", o.singular_size,
      "CAD input: size at re-entrant edges and at the rim of clamped faces, a fraction "
      "of --h, e.g. 0.25; 0 = off. Default: re-entrant edges only, at 0.5 at order 2; off at "
      "order 1");
  sub.add_flag("--no-pyramids", o.no_pyramids,
               "CAD input: make no pyramids (a quad face against two triangles stays NC; at "
               "order 2 its hanging node is tied to the quad where it lies on it, else left free, "
               "with a warning)");
  sub.add_flag("--no-edge-spacing-size", o.no_edge_spacing_size,
               "CAD input: size the edge points by the size field, not by the spacing their "
               "edges got (as on `mesh`)");
  sub.add_flag("--force", o.force,
               "CAD input: allow more than 1 M surface points or 20 M interior points (estimated "
               "before the work), more memory than the machine has available (at least 1.35 GB "
               "per million interior points), and a mesh whose volume is more than 10 % off the "
               "CAD volume");
}

std::vector<int> clamped_cad_faces(const CadModel& cad, const std::vector<std::string>& fix) {
  std::vector<int> faces;
  for (const std::string& text : fix) {
    const FixSpec spec = parse_fix_spec(text);
    if (!(spec.component[0] && spec.component[1] && spec.component[2])) continue;
    if (spec.kind == FixSpec::Kind::Faces)
      faces.insert(faces.end(), spec.faces.begin(), spec.faces.end());
    if (spec.kind != FixSpec::Kind::Coordinates) continue;
    cad.compute_face_boxes();
    for (int f = 1; f <= cad.num_faces(); ++f) {
      const BBox3 b = cad.face_bbox(f);
      const bool inside = std::all_of(spec.conditions.begin(), spec.conditions.end(),
                                      [&](const FixSpec::Condition& c) {
                                        const double lo = b.min[c.axis], hi = b.max[c.axis];
                                        if (c.op == "<") return hi < c.value;
                                        if (c.op == "<=") return hi <= c.value;
                                        if (c.op == ">") return lo > c.value;
                                        return lo >= c.value;
                                      });
      if (inside) faces.push_back(f);
    }
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

std::string GradedEdges::note() const {
  if (fraction <= 0) return "";
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "graded to %g h at singular edges: %zu re-entrant, %zu on the clamped faces' rim%s",
                fraction, reentrant.size(), rim.size(),
                by_default ? " (order 2's default; --singular-size 0: none)" : "");
  return buf;
}

GradedEdges singular_edges_graded(const ModalCliOptions& o, const CadModel& cad) {
  if (given(o.singular_size_given) && !(o.singular_size >= 0 && o.singular_size <= 1))
    throw Error("--singular-size must be a fraction of --h in [0, 1] (0 = off), got " +
                std::to_string(o.singular_size));
  GradedEdges g;
  g.by_default = !given(o.singular_size_given);
  g.fraction = !g.by_default ? o.singular_size : o.order == 2 ? kOrder2ReentrantSize : 0.0;
  if (g.fraction > 0) {
    g.reentrant = reentrant_edges(cad);
    if (!g.by_default) g.rim = rim_edges(cad, clamped_cad_faces(cad, o.fix));
  }
  if (g.reentrant.empty() && g.rim.empty()) g.fraction = 0;  // nothing graded: say nothing
  return g;
}

MeshOptions cad_mesh_options(const ModalCliOptions& o, double h, const GradedEdges& graded) {
  if (given(o.curvature_given) && (o.curvature < 0 || (o.curvature > 0 && o.curvature < 3)))
    throw Error("--curvature must be 0 (off) or at least 3 elements per 2*pi (got " +
                std::to_string(o.curvature) + ")");
  MeshOptions m;
  m.surface.h = h;
  if (given(o.curvature_given)) {
    m.surface.curvature = o.curvature;
  } else if (o.order == 2) {
    m.surface.curvature = kOrder2Curvature;
    m.surface.curvature_min_ratio = kOrder2CurvatureMinRatio;
  }
  parse_size_at(o.size_at, h, m.surface.vertex_sizes, m.surface.face_sizes, m.surface.edge_sizes);
  std::vector<int> edges = graded.reentrant;
  edges.insert(edges.end(), graded.rim.begin(), graded.rim.end());
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (int e : edges) m.surface.edge_sizes.emplace_back(e, graded.fraction * h);
  m.volume.conformal = o.conformal;
  // Not the mesher's default: see modal_cli.hpp.
  m.volume.relax_points = std::max(0, o.relax_points);
  m.volume.coherent_first = o.coherent_first;
  if (o.align_opposite >= 0) m.surface.align_opposite = o.align_opposite;  // else the default
  m.volume.no_pyramids = o.no_pyramids;
  if (o.no_edge_spacing_size) m.surface.sizes_from_edge_spacing = false;
  m.read.glue = o.glue;
  m.surface.force = o.force;  // the point limits' error names --force, as on `mesh`
  return m;
}

namespace {

// "1,4-6" -> 1, 4, 5, 6 (positive ids, at most 100000 in a range).
std::vector<std::int32_t> parse_solid_ids(const std::string& spec, const std::string& text) {
  std::vector<std::int32_t> ids;
  std::size_t pos = 0;
  auto bad = [&]() {
    return Error("--material " + spec + ": expected solid ids like 2 or 1,4-6 before '=', got '" +
                 text + "'");
  };
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    const std::size_t dash = item.find('-');
    try {
      std::size_t used = 0;
      const long lo = std::stol(item.substr(0, dash), &used);
      if (used != item.substr(0, dash).size()) throw bad();
      long hi = lo;
      if (dash != std::string::npos) {
        hi = std::stol(item.substr(dash + 1), &used);
        if (used != item.size() - dash - 1) throw bad();
      }
      if (lo < 1 || hi < lo || hi - lo > 100000 || hi > std::numeric_limits<std::int32_t>::max())
        throw bad();
      for (long i = lo; i <= hi; ++i) ids.push_back(static_cast<std::int32_t>(i));
    } catch (const std::logic_error&) {  // stol: not a number, out of range
      throw bad();
    }
    pos = comma + 1;
  }
  return ids;
}

// "aluminium" or "70e9,0.33,2700".
Material parse_material_value(const std::string& spec, const std::string& text) {
  if (text.find(',') == std::string::npos) return material_by_name(text);
  Material m;
  m.name = "custom";
  double* v[3] = {&m.E, &m.nu, &m.rho};
  std::size_t pos = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t comma = i < 2 ? text.find(',', pos) : text.size();
    std::size_t used = 0;
    const std::string item = comma == std::string::npos ? "" : text.substr(pos, comma - pos);
    try {
      *v[i] = std::stod(item, &used);
    } catch (const std::logic_error&) {
      used = 0;
    }
    if (item.empty() || used != item.size() || (i == 2 && comma != text.size()))
      throw Error("--material " + spec + ": expected a material name or E,nu,rho (Pa, -, kg/m^3)");
    pos = comma + 1;
  }
  if (text.find(',', pos) != std::string::npos)
    throw Error("--material " + spec + ": expected a material name or E,nu,rho (Pa, -, kg/m^3)");
  return m;
}

}  // namespace

SolidMaterials parse_materials(const std::vector<std::string>& specs, const double* E,
                               const double* nu, const double* rho) {
  SolidMaterials out(material_by_name("steel"));
  bool named = false;
  for (const std::string& spec : specs) {
    if (spec.rfind("solid:", 0) != 0) {
      if (named)
        throw Error("--material " + spec + ": a material for every solid is already given");
      out.base = material_by_name(spec);
      named = true;
      continue;
    }
    const std::size_t eq = spec.find('=');
    if (eq == std::string::npos)
      throw Error("--material " + spec + ": expected solid:IDS=NAME or solid:IDS=E,nu,rho");
    const Material m = parse_material_value(spec, spec.substr(eq + 1));
    try {
      validate(m);
    } catch (const Error& e) {
      throw Error("--material " + spec + ": " + e.what());
    }
    for (std::int32_t id : parse_solid_ids(spec, spec.substr(6, eq - 6)))
      out.by_solid.emplace_back(id, m);
  }
  if (E || nu || rho) out.base.name += " (modified)";
  if (E) check_finite("--E", out.base.E = *E);
  if (nu) check_finite("--nu", out.base.nu = *nu);
  if (rho) check_finite("--rho", out.base.rho = *rho);
  validate(out.base);
  std::stable_sort(out.by_solid.begin(), out.by_solid.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  validate(out);  // a solid named twice
  return out;
}

void check_material_solids(const SolidMaterials& m, const CadModel& cad) {
  for (const auto& [solid, mat] : m.by_solid)
    if (solid > cad.num_solids())
      throw Error("--material solid:" + std::to_string(solid) + ": the CAD model has " +
                  std::to_string(cad.num_solids()) + " solid(s), ids 1 to " +
                  std::to_string(cad.num_solids()) + " (hexfem info lists them)");
}

std::string material_summary(const SolidMaterials& m) {
  auto same = [](const Material& a, const Material& b) {
    return a.name == b.name && a.E == b.E && a.nu == b.nu && a.rho == b.rho;
  };
  auto describe = [](const Material& mat) {
    if (mat.name != "custom") return "'" + mat.name + "'";
    char buf[128];
    std::snprintf(buf, sizeof buf, "E = %g Pa, nu = %g, rho = %g kg/m^3", mat.E, mat.nu, mat.rho);
    return std::string(buf);
  };
  std::string s = describe(m.base);
  std::vector<char> done(m.by_solid.size(), 0);
  for (std::size_t i = 0; i < m.by_solid.size(); ++i) {
    if (done[i]) continue;
    std::string ids;
    int count = 0;
    for (std::size_t k = i; k < m.by_solid.size(); ++k)
      if (!done[k] && same(m.by_solid[k].second, m.by_solid[i].second)) {
        done[k] = 1;
        ids += (count++ ? ", " : "") + std::to_string(m.by_solid[k].first);
      }
    s += (count > 1 ? "; solids " : "; solid ") + ids + ": " + describe(m.by_solid[i].second);
  }
  return s;
}

ModalOptions modal_options_from(const ModalCliOptions& o) {
  auto given = [](CLI::Option* opt) { return opt && opt->count() > 0; };
  const SolidMaterials mat =
      parse_materials(o.materials, given(o.E_given) ? &o.E : nullptr,
                      given(o.nu_given) ? &o.nu : nullptr, given(o.rho_given) ? &o.rho : nullptr);
  if (o.order != 1 && o.order != 2)
    throw Error("--order must be 1 or 2 (got " + std::to_string(o.order) + ")");
  if (o.modes < 1) throw Error("--modes must be at least 1 (got " + std::to_string(o.modes) + ")");
  for (const std::string& spec : o.fix) parse_fix_spec(spec);
  ModalOptions opt;
  opt.material = mat;
  opt.fix = o.fix;
  opt.num_modes = o.modes;
  opt.incompatible_hex = incompatible_hex_from_option(o.hex8);
  opt.solver = solver_choice_from_option(o.solver);
  return opt;
}

void check_hex8_for_order(const ModalCliOptions& o, bool order2) {
  if (order2 && given(o.hex8_given))
    throw Error(
        "--hex8 sets the order-1 hexahedron, but this solve is order 2 (the default for a "
        "CAD part): add --order 1");
}

}  // namespace hexfem
