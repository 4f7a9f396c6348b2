// `hexfem info part.step [--json]`: what the CAD file holds, in the ids users name in boundary
// conditions: solids and faces with surface type, area, centroid and bounding box.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "mesher/cad/cad_model.hpp"
#include "mesher/surface_pipeline.hpp"

namespace hexfem {
namespace {

nlohmann::json box_json(const BBox3& b) {
  return {{"min", b.min}, {"max", b.max}};
}

nlohmann::json model_json(const std::string& file, const CadModel& cad) {
  nlohmann::json j;
  j["file"] = file;
  j["format"] = cad.format();
  j["file_unit"] = cad.file_unit();
  j["unit"] = "mm";
  j["unit_scale"] = cad.unit_scale();
  j["warnings"] = cad.warnings();
  for (const std::string& w : touching_lumps(cad)) j["warnings"].push_back(w);
  j["num_vertices"] = cad.num_vertices();
  j["num_edges"] = cad.num_edges();
  j["num_faces"] = cad.num_faces();
  j["volume"] = cad.volume();
  j["area"] = cad.area();
  cad.compute_face_boxes();
  j["bbox"] = box_json(cad.bbox());
  j["solids"] = nlohmann::json::array();
  for (int s = 1; s <= cad.num_solids(); ++s)
    j["solids"].push_back({{"id", s},
                           {"volume", cad.solid_volume(s)},
                           {"bbox", box_json(cad.solid_bbox(s))},
                           {"faces", cad.faces_of_solid(s)}});
  j["faces"] = nlohmann::json::array();
  for (int f = 1; f <= cad.num_faces(); ++f)
    j["faces"].push_back({{"id", f},
                          {"type", surface_type_name(cad.surface_type(f))},
                          {"area", cad.face_area(f)},
                          {"centroid", cad.face_centroid(f)},
                          {"bbox", box_json(cad.face_bbox(f))},
                          {"solids", cad.solids_of_face(f)}});
  return j;
}

void print_text(const std::string& file, const CadModel& cad) {
  cad.compute_face_boxes();
  const BBox3 b = cad.bbox();
  std::printf("%s: %s, file unit %s (lengths below in mm, scale %g)\n", file.c_str(),
              cad.format().c_str(), cad.file_unit().c_str(), cad.unit_scale());
  for (const auto& w : cad.warnings()) std::printf("note: %s\n", w.c_str());
  for (const auto& w : touching_lumps(cad)) std::printf("note: %s\n", w.c_str());
  std::printf("%d solid(s), %d faces, %d edges, %d vertices\n", cad.num_solids(), cad.num_faces(),
              cad.num_edges(), cad.num_vertices());
  std::printf("volume %.6g mm^3, area %.6g mm^2\n", cad.volume(), cad.area());
  std::printf("bbox [%g %g %g] - [%g %g %g]\n", b.min[0], b.min[1], b.min[2], b.max[0], b.max[1],
              b.max[2]);
  std::printf("\nsolid  volume        faces  bbox\n");
  for (int s = 1; s <= cad.num_solids(); ++s) {
    const BBox3 sb = cad.solid_bbox(s);
    std::printf("%5d  %-12.6g  %5zu  [%g %g %g] - [%g %g %g]\n", s, cad.solid_volume(s),
                cad.faces_of_solid(s).size(), sb.min[0], sb.min[1], sb.min[2], sb.max[0], sb.max[1],
                sb.max[2]);
  }
  std::printf("\nface  type        area          centroid                          bbox\n");
  for (int f = 1; f <= cad.num_faces(); ++f) {
    const Vec3 c = cad.face_centroid(f);
    const BBox3 fb = cad.face_bbox(f);
    std::printf("%4d  %-10s  %-12.6g  (%10.4g %10.4g %10.4g)  [%g %g %g] - [%g %g %g]\n", f,
                surface_type_name(cad.surface_type(f)), cad.face_area(f), c[0], c[1], c[2],
                fb.min[0], fb.min[1], fb.min[2], fb.max[0], fb.max[1], fb.max[2]);
  }
}

RegisterCommand reg{{"info", "List the solids and faces of a CAD file (ids, types, areas, boxes)",
                     [](CLI::App& sub) {
                       auto file = std::make_shared<std::string>();
                       auto json = std::make_shared<bool>(false);
                       auto glue = std::make_shared<bool>(false);
                       sub.add_option("file", *file, "STEP, IGES or BREP file")->required();
                       sub.add_flag("--json", *json, "print JSON on stdout");
                       sub.add_flag(
                           "--glue", *glue,
                           "the solids as `--glue` bonds them where they touch or overlap");
                       return [=] {
                         check_input_file(*file);
                         const CadModel cad = CadModel::read(*file, CadReadOptions{*glue});
                         if (*json)
                           std::printf("%s\n", model_json(*file, cad).dump(2).c_str());
                         else
                           print_text(*file, cad);
                         return 0;
                       };
                     }}};

}  // namespace
}  // namespace hexfem
