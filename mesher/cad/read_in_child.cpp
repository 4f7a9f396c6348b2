// A CAD read in a forked child. OpenCASCADE's STEP and IGES translators crash the process on
// some damaged files (a null curve dereferenced in StepToGeom::MakeCurve2d; B-spline arrays
// never filled in IGESGeom_BSplineSurface::Init), before any check of ours can run. So the read
// runs in a child, the way tetrahedralize.cpp runs TetGen, and the shape comes back as OCCT
// binary BREP (exact doubles: the same shape as an in-process read).
#include "mesher/cad/read_in_child.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <BinTools.hxx>
#include <Standard_Failure.hxx>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {

namespace fs = std::filesystem;

// The child's answer, in the shared file: a first line "shape", then the unit scale ("%a", exact),
// the unit name, the number of warnings and one per line, and the shape as binary BREP; or
// "error" / "occt" and the message of the hexfem::Error / Standard_Failure thrown.
std::string shared_file(int fd) {
  return "/proc/self/fd/" + std::to_string(fd);
}

// Runs in the child; returns its exit status (0: the answer is complete). Without
// `shape_back` the answer is "probed" alone: the read went through.
int answer_in_child(const ReadHere& read_here, bool shape_back, int fd) {
  std::ofstream out;
  // An error while the shape is written replaces what was written (trunc).
  auto answer = [&](const std::string& kind, const std::string& text) {
    out.close();
    out.open(shared_file(fd), std::ios::binary | std::ios::trunc);
    out << kind << '\n' << text;
  };
  try {
    CadModel::Impl m;
    const TopoDS_Shape shape = read_here(m);
    if (!shape_back) {
      answer("probed", "");
      out.close();
      return out ? 0 : 3;
    }
    char scale[64];
    std::snprintf(scale, sizeof scale, "%a", m.unit_scale);
    std::string head =
        std::string(scale) + '\n' + m.file_unit + '\n' + std::to_string(m.warnings.size()) + '\n';
    for (const std::string& w : m.warnings) head += w + '\n';
    answer("shape", head);
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

}  // namespace

std::string quoted(const fs::path& path) {
  // Not "'" + path.string() + "'": GCC 12 warns falsely about it (-Wrestrict, bug 105329).
  std::string q = path.string();
  q.insert(q.begin(), '\'');
  q.push_back('\'');
  return q;
}

TopoDS_Shape read_in_child(const fs::path& path, const std::string& format,
                           const ReadHere& read_here, CadModel::Impl& m, ChildRead mode) {
  const bool shape_back = mode == ChildRead::kShapeBack;
  const std::string unreadable = quoted(path) + " is not a readable " + format + " file";
  const int fd = ::memfd_create("hexfem-cad-read", MFD_CLOEXEC);
  if (fd < 0) throw Error(format + ": cannot create shared memory for the reader's answer");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } const closer{fd};
  // Nothing buffered may be written twice (by both processes).
  std::cout.flush();
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw Error(format + ": cannot fork the reader");
  if (pid == 0) {
    // The reader's own prints (and glibc's words when it crashes) stay off hexfem's stdout,
    // which carries --json, and off its one-line error.
    const int devnull = ::open("/dev/null", O_WRONLY);
    if (devnull >= 0) {
      ::dup2(devnull, STDOUT_FILENO);
      ::dup2(devnull, STDERR_FILENO);
    }
    ::_exit(answer_in_child(read_here, shape_back, fd));
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status)) throw Error(unreadable + " (OpenCASCADE's reader crashed on it)");
  std::ifstream in(shared_file(fd), std::ios::binary);
  std::string kind, text;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !std::getline(in, kind))
    throw Error(unreadable + " (its reader failed, exit status " +
                std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  if (kind == "probed") return read_here(m);  // it went through there: the same read here
  if (kind != "shape") {
    std::getline(in, text, '\0');
    throw Error(kind == "occt" ? "OpenCASCADE failed on " + quoted(path) + ": " + text : text);
  }
  std::getline(in, text);
  m.unit_scale = std::strtod(text.c_str(), nullptr);
  std::getline(in, m.file_unit);
  std::getline(in, text);
  for (long n = std::strtol(text.c_str(), nullptr, 10); n > 0 && std::getline(in, text); --n)
    m.warnings.push_back(text);
  TopoDS_Shape shape;
  BinTools::Read(shape, in);
  return shape;
}

}  // namespace hexfem
