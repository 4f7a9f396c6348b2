// Reading IGES files. OpenCASCADE's IGES reader crashes the process on some damaged files: a
// truncated parameter section gives B-spline surfaces built from arrays never filled
// (IGESGeom_BSplineSurface::Init, inside IGESControl_Reader::ReadFile, before any load check can
// run). So the read runs in a forked child, the way tetrahedralize.cpp runs TetGen; the shape
// comes back as OCCT binary BREP (exact doubles: the same shape as an in-process read).
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <BinTools.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_Check.hxx>
#include <Interface_Static.hxx>
#include <Standard_Failure.hxx>
#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "mesher/cad/cad_impl.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {

namespace fs = std::filesystem;

std::string quoted(const fs::path& path) {
  return "'" + path.string() + "'";
}

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

// The child's answer, in the shared file: a first line "shape", then the unit scale ("%a", exact),
// the unit name and the shape as binary BREP; or "error" / "occt" and the message of the
// hexfem::Error / Standard_Failure thrown.
std::string shared_file(int fd) {
  return "/proc/self/fd/" + std::to_string(fd);
}

// Runs in the child; returns its exit status (0: the answer is complete).
int answer_in_child(const fs::path& path, int fd) {
  std::ofstream out;
  // An error while the shape is written replaces what was written (trunc).
  auto answer = [&](const std::string& kind, const std::string& text) {
    out.close();
    out.open(shared_file(fd), std::ios::binary | std::ios::trunc);
    out << kind << '\n' << text;
  };
  try {
    CadModel::Impl m;
    const TopoDS_Shape shape = read_iges_here(path, m);
    char scale[64];
    std::snprintf(scale, sizeof scale, "%a", m.unit_scale);
    answer("shape", std::string(scale) + '\n' + m.file_unit + '\n');
    BinTools::Write(shape, out);
  } catch (const Error& e) {
    answer("error", e.what());
  } catch (const Standard_Failure& e) {
    answer("occt", e.GetMessageString());
  } catch (...) {
    return 2;
  }
  out.close();
  return out ? 0 : 3;
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
  const int fd = ::memfd_create("hexfem-iges", MFD_CLOEXEC);
  if (fd < 0) throw Error("IGES: cannot create shared memory for the reader's answer");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } const closer{fd};
  // Nothing buffered may be written twice (by both processes).
  std::cout.flush();
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw Error("IGES: cannot fork the reader");
  if (pid == 0) {
    // The reader's own prints (and glibc's words when it crashes) stay off hexfem's stdout,
    // which carries --json, and off its one-line error.
    const int devnull = ::open("/dev/null", O_WRONLY);
    if (devnull >= 0) {
      ::dup2(devnull, STDOUT_FILENO);
      ::dup2(devnull, STDERR_FILENO);
    }
    ::_exit(answer_in_child(path, fd));
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status))
    throw Error(quoted(path) + " is not a readable IGES file (OpenCASCADE's reader crashed on it)");
  std::ifstream in(shared_file(fd), std::ios::binary);
  std::string kind, text;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !std::getline(in, kind))
    throw Error(quoted(path) + " is not a readable IGES file (its reader failed, exit status " +
                std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  if (kind != "shape") {
    std::getline(in, text, '\0');
    throw Error(kind == "occt" ? "OpenCASCADE failed on " + quoted(path) + ": " + text : text);
  }
  std::getline(in, text);
  m.unit_scale = std::strtod(text.c_str(), nullptr);
  std::getline(in, m.file_unit);
  TopoDS_Shape shape;
  BinTools::Read(shape, in);
  return shape;
}

}  // namespace hexfem
