// Reading IGES files. OpenCASCADE's IGES reader crashes the process on some damaged files: a
// truncated parameter section gives B-spline surfaces built from arrays never filled
// (IGESGeom_BSplineSurface::Init, inside IGESControl_Reader::ReadFile, before any load check can
// run). So the read runs in a forked child (read_in_child.cpp).
#include <IGESControl_Reader.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_Check.hxx>
#include <Interface_Static.hxx>
#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <string>

#include "mesher/cad/cad_impl.hpp"
#include "mesher/cad/read_in_child.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {

namespace fs = std::filesystem;

// The IGES B-rep entities (manifold solid 186; vertex list 502 to shell 514): the translator
// follows their pointers without looking, so one that failed to load is refused.
bool is_brep_entity(int type) {
  return type == 186 || (type >= 502 && type <= 514);
}

// A face whose loop pointer names no entry of the file (or an entry of another type) loads with a
// fail and a null loop, which IGESToBRep_BRepEntity::TransferLoop then dereferences.
void check_iges_entities(const fs::path& path, const IGESData_IGESModel& model) {
  for (int i = 1; i <= model.NbEntities(); ++i) {
    if (!model.IsErrorEntity(i)) continue;
    const Handle(IGESData_IGESEntity) e = model.Entity(i);
    if (e.IsNull() || !is_brep_entity(e->TypeNumber())) continue;
    const Handle(Interface_Check) check = model.Check(i, true);
    std::string why = !check.IsNull() && check->NbFails() > 0 ? check->CFail(1) : "";
    // OCCT leaves the parameter number out of this message ("parameter %d (Loop of the Face)").
    if (const auto at = why.find(" %d"); at != std::string::npos) why.erase(at, 3);
    throw Error(quoted(path) + " is not a readable IGES file: entry " +
                std::to_string(model.DNum(e)) + " (type " + std::to_string(e->TypeNumber()) +
                ") is corrupt" + (why.empty() ? "" : " (" + why + ")"));
  }
}

// The read itself, in the child. Records the file's unit in `m`.
TopoDS_Shape read_iges_here(const fs::path& path, CadModel::Impl& m) {
  IGESControl_Reader reader;
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  if (reader.ReadFile(path.string().c_str()) != IFSelect_RetDone)
    throw Error(quoted(path) + " is not a readable IGES file");
  check_iges_entities(path, *reader.IGESModel());
  const auto& global = reader.IGESModel()->GlobalSection();
  const Handle(TCollection_HAsciiString) name = global.UnitName();
  // IGES global section unit flag (IGES 5.3, section 2.2.4.3, parameter 14).
  static const std::array<const char*, 12> kFlagUnits = {
      "", "inch", "mm", "", "ft", "mi", "m", "km", "mil", "um", "cm", "microinch"};
  const int flag = global.UnitFlag();
  std::string unit = flag > 0 && flag < 12 ? kFlagUnits[flag] : "";
  if (unit.empty() && !name.IsNull()) unit = lower_case(name->ToCString());
  if (unit == "microinch") {
    m.unit_scale = 25.4e-6;
  } else {
    m.unit_scale = mm_per_unit(unit);
  }
  if (m.unit_scale == 0.0) throw Error("IGES file unit '" + unit + "' is not supported");
  m.file_unit = unit;
  if (reader.TransferRoots() == 0 || reader.NbShapes() == 0)
    throw Error(quoted(path) + " contains no shape that can be transferred");
  return reader.OneShape();
}

// Whether the file's last record is its Terminate section (IGES 5.3, section 2.2.6: "T" in
// column 73). A file cut short has none.
bool has_terminate_section(const fs::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in.tellg();
  const std::streamoff n = std::min<std::streamoff>(size, 400);
  std::string tail(static_cast<std::size_t>(n), '\0');
  in.seekg(size - n);
  in.read(tail.data(), n);
  // Blank lines, NUL padding and a DOS end-of-file mark after it are left to the reader.
  while (!tail.empty() && (std::isspace(static_cast<unsigned char>(tail.back())) ||
                           tail.back() == '\0' || tail.back() == '\x1a'))
    tail.pop_back();
  const auto nl = tail.find_last_of("\r\n");
  // Files without line breaks hold 80-column records back to back.
  const std::string last = nl != std::string::npos ? tail.substr(nl + 1)
                           : tail.size() >= 80     ? tail.substr(tail.size() - 80)
                                                   : tail;
  return last.size() >= 73 && last[72] == 'T';
}

}  // namespace

TopoDS_Shape read_iges(const fs::path& path, CadModel::Impl& m) {
  // OpenCASCADE reads what is left of a file cut short, and may crash on it or return a part of
  // the model as if it were all (bearing.iges cut at 1.1 MB: one solid sewn from 178 surfaces).
  if (!has_terminate_section(path))
    throw Error(quoted(path) + " is not a readable IGES file: it has no Terminate section " +
                "(truncated?)");
  return read_in_child(
      path, "IGES", [&](CadModel::Impl& here) { return read_iges_here(path, here); }, m);
}

}  // namespace hexfem
