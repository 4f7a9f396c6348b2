#include "app/modal_cli.hpp"

#include <algorithm>
#include <cstdio>

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
  sub.add_option("--material", o.material, "steel | aluminium | titanium (default steel)");
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
  sub.add_option("--curvature", o.curvature,
                 "CAD input: curvature bound, N elements per 2*pi on curved edges and faces (0 = "
                 "off). Default: " +
                     std::to_string(kOrder2Curvature) +
                     " at order 2 (never finer than h/2 from it), off at order 1");
  sub.add_option("--relax-points", o.relax_points,
                 "CAD input: sweeps moving each interior point towards its lattice neighbours "
                 "(mesher study switch, as on `mesh`)")
      ->check(CLI::Range(0, 1000));
  sub.add_option("--align-opposite", o.align_opposite,
                 "CAD input: pack the two faces of a wall up to T sizes thick from the same points "
                 "(mesher study switch, as on `mesh`)")
      ->check(CLI::Range(0.0, 10.0));
  sub.add_flag("--glue", o.glue, std::string("CAD input: ") + kGlueHelp);
  sub.add_option("--singular-size", o.singular_size,
                 "CAD input: size at re-entrant edges and at the rim of clamped faces, a fraction "
                 "of --h, e.g. 0.25 (default: off)");
  sub.add_flag("--no-pyramids", o.no_pyramids,
               "CAD input: make no pyramids (a quad face against two triangles stays NC; tied at "
               "order 2)");
  sub.add_flag("--force", o.force,
               "CAD input: accept a mesh whose volume is more than 10 % off the CAD volume");
}

std::vector<int> clamped_cad_faces(const CadModel& cad, const std::vector<std::string>& fix) {
  std::vector<int> faces;
  for (const std::string& text : fix) {
    const FixSpec spec = parse_fix_spec(text);
    if (!(spec.component[0] && spec.component[1] && spec.component[2])) continue;
    if (spec.kind == FixSpec::Kind::Faces)
      faces.insert(faces.end(), spec.faces.begin(), spec.faces.end());
    if (spec.kind != FixSpec::Kind::Coordinates) continue;
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
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "graded to %g h at singular edges: %zu re-entrant, %zu on the clamped faces' rim",
                fraction, reentrant.size(), rim.size());
  return buf;
}

GradedEdges singular_edges_graded(const ModalCliOptions& o, const CadModel& cad) {
  if (o.singular_size != -1 && !(o.singular_size >= 0 && o.singular_size <= 1))
    throw Error("--singular-size must be a fraction of --h in [0, 1] (0 = off), got " +
                std::to_string(o.singular_size));
  GradedEdges g;
  g.fraction = std::max(0.0, o.singular_size);
  if (g.fraction > 0) {
    g.reentrant = reentrant_edges(cad);
    g.rim = rim_edges(cad, clamped_cad_faces(cad, o.fix));
  }
  return g;
}

MeshOptions cad_mesh_options(const ModalCliOptions& o, double h, const GradedEdges& graded) {
  if (o.curvature != -1 && (o.curvature < 0 || (o.curvature > 0 && o.curvature < 3)))
    throw Error("--curvature must be 0 (off) or at least 3 elements per 2*pi (got " +
                std::to_string(o.curvature) + ")");
  MeshOptions m;
  m.surface.h = h;
  if (o.curvature >= 0) {
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
  m.volume.relax_points = std::max(0, o.relax_points);
  m.surface.align_opposite = std::max(0.0, o.align_opposite);
  m.volume.no_pyramids = o.no_pyramids;
  m.read.glue = o.glue;
  return m;
}

ModalOptions modal_options_from(const ModalCliOptions& o) {
  Material mat = material_by_name(o.material);
  const bool E = o.E_given && o.E_given->count(), nu = o.nu_given && o.nu_given->count(),
             rho = o.rho_given && o.rho_given->count();
  if (E || nu || rho) mat.name += " (modified)";
  if (E) check_finite("--E", mat.E = o.E);
  if (nu) check_finite("--nu", mat.nu = o.nu);
  if (rho) check_finite("--rho", mat.rho = o.rho);
  validate(mat);
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
  if (order2 && o.hex8_given && o.hex8_given->count() > 0)
    throw Error(
        "--hex8 sets the order-1 hexahedron, but this solve is order 2 (the default for a "
        "CAD part): add --order 1");
}

}  // namespace hexfem
