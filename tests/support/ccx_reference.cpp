#include "tests/support/ccx_reference.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

void write_elements(std::ostream& out, const MixedMesh& mesh, CellKind kind, const char* type) {
  bool header = false;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (mesh.cell_kind[c] != kind) continue;
    if (!header) out << "*ELEMENT, TYPE=" << type << ", ELSET=EALL\n";
    header = true;
    const std::int32_t* v = mesh.cell(c);
    out << c + 1;
    if (kind == CellKind::Pyramid5) {
      for (int i = 0; i < 8; ++i) out << ", " << v[i < 4 ? i : 4] + 1;
    } else {
      for (int i = 0; i < num_nodes(kind); ++i) out << ", " << v[i] + 1;
    }
    out << '\n';
  }
}

bool numbers(const std::string& line, std::vector<double>& v) {
  std::istringstream s(line);
  v.clear();
  std::string tok;
  while (s >> tok) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(tok, &used));
      if (used != tok.size()) return false;
    } catch (...) {
      return false;
    }
  }
  return !v.empty();
}

std::string tail(const std::filesystem::path& file, std::size_t lines) {
  std::ifstream in(file);
  std::vector<std::string> all;
  for (std::string l; std::getline(in, l);) all.push_back(l);
  std::string out;
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i)
    out += (out.empty() ? "" : " | ") + all[i];
  return out;
}

}  // namespace

void write_ccx_frequency_deck(std::ostream& out, const MixedMesh& mesh,
                              const std::vector<std::uint8_t>& fixed, const SolidMaterials& mats,
                              int modes, double length_scale) {
  char buf[160];
  out << "*HEADING\nhexfem: modal reference deck (SI units)\n*NODE, NSET=NALL\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    const Vec3& x = mesh.nodes[i];
    std::snprintf(buf, sizeof buf, "%zu, %.17g, %.17g, %.17g\n", i + 1, x[0] * length_scale,
                  x[1] * length_scale, x[2] * length_scale);
    out << buf;
  }
  write_elements(out, mesh, CellKind::Hex8, "C3D8");
  write_elements(out, mesh, CellKind::Pyramid5, "C3D8");
  write_elements(out, mesh, CellKind::Wedge6, "C3D6");
  write_elements(out, mesh, CellKind::Tet4, "C3D4");
  bool any = false;
  for (std::size_t i = 0; i < fixed.size(); ++i)
    if (fixed[i]) {
      if (!any) out << "*BOUNDARY\n";
      any = true;
      out << i / 3 + 1 << ", " << i % 3 + 1 << ", " << i % 3 + 1 << '\n';
    }
  // One material and section per set of cells: the solids listed in mats.by_solid each, the
  // other cells (ELSET REST) the base material.
  auto material = [&](const std::string& name, const Material& m, const std::string& elset) {
    std::snprintf(buf, sizeof buf, "%.17g, %.17g\n", m.E, m.nu);
    out << "*MATERIAL, NAME=" << name << "\n*ELASTIC\n" << buf;
    std::snprintf(buf, sizeof buf, "%.17g\n", m.rho);
    out << "*DENSITY\n"
        << buf << "*SOLID SECTION, ELSET=" << elset << ", MATERIAL=" << name << "\n";
  };
  if (mats.by_solid.empty()) {
    material("MAT", mats.base, "EALL");
  } else {
    std::vector<char> listed(mesh.num_cells(), 0);
    for (const auto& [solid, m] : mats.by_solid) {
      const std::string set = "SOLID" + std::to_string(solid);
      out << "*ELSET, ELSET=" << set << "\n";
      for (std::size_t c = 0; c < mesh.num_cells(); ++c)
        if (mesh.cell_solid[c] == solid) {
          out << c + 1 << "\n";
          listed[c] = 1;
        }
      material("MAT" + std::to_string(solid), m, set);
    }
    if (std::find(listed.begin(), listed.end(), 0) != listed.end()) {
      out << "*ELSET, ELSET=REST\n";
      for (std::size_t c = 0; c < mesh.num_cells(); ++c)
        if (!listed[c]) out << c + 1 << "\n";
      material("MAT", mats.base, "REST");
    }
  }
  out << "*STEP\n*FREQUENCY\n" << modes << "\n*END STEP\n";
}

CcxModalOutput parse_ccx_dat(std::istream& dat) {
  CcxModalOutput out;
  // Blocks: eigenvalues (rows "mode eigenvalue ω f imag"), effective modal mass (rows "mode x y
  // z rx ry rz", closed by a "TOTAL" row), total effective mass (one row "x y z rx ry rz").
  enum { kNone, kEigen, kMass, kTotal } block = kNone;
  std::vector<double> v;
  for (std::string line; std::getline(dat, line);) {
    if (line.find("E I G E N V A L U E   O U T P U T") != std::string::npos) {
      block = kEigen;
    } else if (line.find("E F F E C T I V E   M O D A L   M A S S") != std::string::npos) {
      block = kMass;
    } else if (line.find("T O T A L   E F F E C T I V E   M A S S") != std::string::npos) {
      block = kTotal;
    } else if (line.find("P A R T I C I P A T I O N") != std::string::npos ||
               line.find("TOTAL") != std::string::npos) {
      block = kNone;
    } else if (block != kNone && numbers(line, v)) {
      if (block == kEigen && v.size() >= 4 && v[0] == static_cast<int>(v[0])) {
        out.eigenvalues.push_back(v[1]);
        out.frequencies.push_back(std::copysign(std::sqrt(std::abs(v[1])), v[1]) / (2 * M_PI));
      } else if (block == kMass && v.size() >= 4) {
        out.effective_mass.push_back({v[1], v[2], v[3]});
      } else if (block == kTotal && v.size() >= 3) {
        out.total_mass = v[0];
        block = kNone;
      }
    }
  }
  if (out.eigenvalues.empty())
    throw Error("ccx .dat has no E I G E N V A L U E   O U T P U T block");
  return out;
}

CcxRun run_ccx_frequency(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                         const SolidMaterials& mats, int modes, const std::filesystem::path& dir,
                         const std::string& name, double length_scale, int threads) {
  std::filesystem::create_directories(dir);
  const std::filesystem::path inp = dir / (name + ".inp"), dat = dir / (name + ".dat"),
                              log = dir / (name + ".log");
  write_atomically(inp, false, [&](std::ostream& out) {
    write_ccx_frequency_deck(out, mesh, fixed, mats, modes, length_scale);
  });
  std::error_code ec;
  std::filesystem::remove(dat, ec);

  CcxRun run;
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw Error("cannot start ccx (fork failed)");
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(126);
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
      close(fd);
    }
    const std::string t = std::to_string(threads);
    setenv("OMP_NUM_THREADS", t.c_str(), 1);
    setenv("CCX_NPROC_EQUATION_SOLVER", t.c_str(), 1);
    execlp("ccx", "ccx", name.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  rusage ru{};
  if (wait4(pid, &status, 0, &ru) < 0) throw Error("waiting for ccx failed");
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  run.peak_rss_kb = ru.ru_maxrss;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (run.exit_code == 127) throw Error("ccx not found on PATH (Debian package calculix-ccx)");
  std::ifstream in(dat);
  if (run.exit_code != 0 || !in)
    throw Error("ccx failed (exit " + std::to_string(run.exit_code) + "): " + tail(log, 5));
  run.output = parse_ccx_dat(in);
  return run;
}

}  // namespace hexfem
