// Modal-solver study program: `bench_modal <study> [options]`, each study prints a Markdown table
// (validation/solver.md collects them).
//   benchmark [k ...] [--no-ccx] [--ccx-threads N] [--ccx-mem-gb G] [--ccx-cpu-s S] [--ncv N]
//       10 modes of the 100x10x10 mm steel cantilever, hex8 (10k x k x k), clamped at x = 0:
//       wall time, peak memory (each run in its own child process, getrusage) and the same mesh
//       through CalculiX in the same run. Default k = 14 21 32 (~95k, ~306k, ~1.05M DOF).
//       --ccx-mem-gb / --ccx-cpu-s cap ccx's address space / CPU time (it then counts as failed).
//   iterative [k ...] [--no-direct] [--ranks N --hexfem PATH]
//       the same cantilevers through both paths in one run, each in its own child process:
//       direct (CHOLMOD + Spectra) and iterative (LOBPCG + GAMG) time, peak memory, ratios
//       and the largest relative difference of f1-f10. Default k = 14 21 32. --ranks N adds
//       the iterative path under `mpirun -n N PATH modal` on the same mesh written to a file
//       (its report's assembly + setup + solve; peak memory summed over the ranks).
//   write-mesh k file.msh   the k cantilever as a mesh file (for `mpirun ... hexfem modal`).
//   ccx          hexfem vs ccx C3D8/C3D6/C3D4 on the 40x4x4 cantilever, relative differences.
//   convergence  tet4 / wedge6 / pyramid+tet cantilevers converging towards hex8.
//   euler        first bending of a slender hex beam vs Euler-Bernoulli.
//   fv52         NAFEMS FV52 thick plate on hex meshes.
//   nc           hex next to two tets (non-conformal quad faces) vs conformal refinements.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fem/boundary.hpp"
#include "fem/modal_solver.hpp"
#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/structured_box.hpp"
#include "tests/support/ccx_reference.hpp"

using namespace hexfem;

namespace {

const Material kSteel{"steel", 210e9, 0.3, 7850};

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::filesystem::path scratch(const std::string& name) {
  const char* env = std::getenv("HEXFEM_BENCH_DIR");
  const std::filesystem::path dir =
      std::filesystem::path(env ? env : std::filesystem::temp_directory_path().string()) /
      ("hexfem_bench_" + std::to_string(::getpid())) / name;
  std::filesystem::create_directories(dir);
  return dir;
}

// Runs `fn` in a child process; it fills a fixed-size array of doubles sent back through a pipe.
// Returns the values and the child's peak resident memory (kB).
struct ChildResult {
  std::vector<double> values;
  long peak_rss_kb = 0;
  bool ok = false;
};
ChildResult in_child(std::size_t count, const std::function<std::vector<double>()>& fn) {
  int fd[2];
  if (pipe(fd) != 0) throw Error("pipe failed");
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    std::vector<double> v;
    try {
      v = fn();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "child: %s\n", e.what());
      _exit(1);
    }
    v.resize(count, NAN);
    const ssize_t n = write(fd[1], v.data(), count * sizeof(double));
    _exit(n == static_cast<ssize_t>(count * sizeof(double)) ? 0 : 1);
  }
  close(fd[1]);
  ChildResult r;
  r.values.resize(count, NAN);
  std::size_t got = 0;
  while (got < count * sizeof(double)) {
    const ssize_t n =
        read(fd[0], reinterpret_cast<char*>(r.values.data()) + got, count * sizeof(double) - got);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  close(fd[0]);
  int status = 0;
  rusage ru{};
  wait4(pid, &status, 0, &ru);
  r.peak_rss_kb = ru.ru_maxrss;
  r.ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && got == count * sizeof(double);
  return r;
}

ModalOptions cantilever_options(int modes) {
  ModalOptions o;
  o.material = kSteel;
  o.fix = {"face:1"};
  o.num_modes = modes;
  o.length_scale = 1e-3;
  return o;
}

// ---------------------------------------------------------------------------------------------
int benchmark(const std::vector<std::string>& args) {
  std::vector<int> ks;
  bool run_ccx = true;
  int ccx_threads = 2, ncv = 0;
  double ccx_mem_gb = 0, ccx_cpu_s = 0;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--no-ccx")
      run_ccx = false;
    else if (args[i] == "--ccx-mem-gb" && i + 1 < args.size())
      ccx_mem_gb = std::stod(args[++i]);
    else if (args[i] == "--ccx-cpu-s" && i + 1 < args.size())
      ccx_cpu_s = std::stod(args[++i]);
    else if (args[i] == "--ncv" && i + 1 < args.size())
      ncv = std::stoi(args[++i]);
    else if (args[i] == "--ccx-threads" && i + 1 < args.size())
      ccx_threads = std::stoi(args[++i]);
    else
      ks.push_back(std::stoi(args[i]));
  }
  if (ks.empty()) ks = {14, 21, 32};
  const int modes = 10;
  std::printf(
      "| mesh (hex8) | DOF | assembly s | factor s | Lanczos s | hexfem total s | hexfem peak MB "
      "| factor nnz | ccx s | ccx peak MB | max rel. diff f1-f10 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int k : ks) {
    const int nx = 10 * k;
    // Fields: dofs, assemble, factor, solve, total, nnz, f1..f10
    const ChildResult mine = in_child(6 + modes, [&] {
      const MixedMesh mesh = make_box_mesh({100, 10, 10}, nx, k, k, CellKind::Hex8);
      const double t0 = now();
      ModalOptions opt = cantilever_options(modes);
      opt.eigen.ncv = ncv;
      const ModalResult r = solve_modal(mesh, opt);
      const double total = now() - t0;
      std::vector<double> v = {double(r.num_free_dofs),
                               r.assemble_seconds,
                               r.eigen.factor_seconds,
                               r.eigen.solve_seconds,
                               total,
                               double(r.eigen.factor_nnz)};
      std::fprintf(stderr, "k=%d: order %.2f s, factor %.3g flops (%.2f GFlop/s)\n", k,
                   r.order_seconds, r.eigen.factor_flops,
                   r.eigen.factor_flops / r.eigen.factor_seconds / 1e9);
      for (double f : r.frequencies) v.push_back(f);
      std::fprintf(stderr, "k=%d: %ld DOF, %ld Lanczos restarts, %ld solves, residual %.1e\n", k,
                   r.num_free_dofs, r.eigen.iterations, r.eigen.operations, r.eigen.max_residual);
      return v;
    });
    std::string ccx_cols = "| — | — | — |";
    if (run_ccx && mine.ok) {
      const MixedMesh mesh = make_box_mesh({100, 10, 10}, nx, k, k, CellKind::Hex8);
      const std::vector<std::uint8_t> fixed = select_fixed_dofs(mesh, {"face:1"});
      // Optional caps for ccx (inherited by its process): address space and CPU seconds, so a
      // run too big for the machine fails instead of pushing others out of memory.
      rlimit old_as{}, old_cpu{};
      getrlimit(RLIMIT_AS, &old_as);
      getrlimit(RLIMIT_CPU, &old_cpu);
      if (ccx_mem_gb > 0) {
        rlimit r = old_as;
        r.rlim_cur = static_cast<rlim_t>(ccx_mem_gb * 1024 * 1024 * 1024);
        setrlimit(RLIMIT_AS, &r);
      }
      if (ccx_cpu_s > 0) {
        rlimit r = old_cpu;
        r.rlim_cur = static_cast<rlim_t>(ccx_cpu_s);
        setrlimit(RLIMIT_CPU, &r);
      }
      try {
        const CcxRun ccx =
            run_ccx_frequency(mesh, fixed, kSteel, modes, scratch("ccx_" + std::to_string(k)),
                              "cantilever", 1e-3, ccx_threads);
        double diff = 0;
        for (int i = 0; i < modes && i < static_cast<int>(ccx.output.frequencies.size()); ++i)
          diff = std::max(diff, std::abs(mine.values[6 + i] / ccx.output.frequencies[i] - 1));
        char buf[160];
        std::snprintf(buf, sizeof buf, "| %.1f | %.0f | %.1e |", ccx.seconds,
                      ccx.peak_rss_kb / 1024.0, diff);
        ccx_cols = buf;
      } catch (const Error& e) {
        std::fprintf(stderr, "ccx k=%d: %s\n", k, e.what());
        ccx_cols = "| failed | — | — |";
      }
      setrlimit(RLIMIT_AS, &old_as);
      setrlimit(RLIMIT_CPU, &old_cpu);
    }
    if (!mine.ok) {
      std::printf("| %dx%dx%d | — | hexfem failed | | | | %.0f | | | | |\n", nx, k, k,
                  mine.peak_rss_kb / 1024.0);
      continue;
    }
    const auto& v = mine.values;
    std::printf("| %dx%dx%d | %.0f | %.2f | %.2f | %.2f | %.2f | %.0f | %.3g %s f1 = %.4f Hz\n", nx,
                k, k, v[0], v[1], v[2], v[3], v[4], mine.peak_rss_kb / 1024.0, v[5],
                ccx_cols.c_str(), v[6]);
    std::fflush(stdout);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// Fields: dofs, assembly, setup, solve, total, iterations, max residual, f1..f10.
ChildResult run_path(int k, SolverChoice path, int modes) {
  return in_child(7 + modes, [&] {
    const MixedMesh mesh = make_box_mesh({100, 10, 10}, 10 * k, k, k, CellKind::Hex8);
    const double t0 = now();
    ModalOptions opt = cantilever_options(modes);
    opt.solver = path;
    const ModalResult r = solve_modal(mesh, opt);
    const double total = now() - t0;
    std::vector<double> v = {double(r.num_free_dofs),
                             r.assemble_seconds + r.order_seconds,
                             r.eigen.setup_seconds,
                             r.eigen.solve_seconds,
                             total,
                             double(r.eigen.iterations),
                             r.eigen.max_residual};
    for (double f : r.frequencies) v.push_back(f);
    return v;
  });
}

std::string load_average() {
  double l[3] = {0, 0, 0};
  return getloadavg(l, 3) == 3 ? std::to_string(l[0]).substr(0, 4) : "?";
}

// The iterative path under `mpirun -n ranks hexfem modal` on the same cantilever written to a
// file: its report's assembly, setup and solve times, summed peak memory and iterations.
// Fields as run_path's; ok = false when the run fails.
ChildResult run_mpi(int k, int ranks, const std::string& hexfem, int modes) {
  ChildResult r;
  const std::filesystem::path dir = scratch("mpi_" + std::to_string(k));
  const std::string mesh = (dir / "cantilever.msh").string(), json = (dir / "report.json").string();
  write_mesh(make_box_mesh({100, 10, 10}, 10 * k, k, k, CellKind::Hex8), mesh);
  const std::string cmd = "OMP_NUM_THREADS=1 mpirun --allow-run-as-root -x OMP_NUM_THREADS -n " +
                          std::to_string(ranks) + " " + hexfem + " modal " + mesh +
                          " --units mm --fix face:1 --hex8 full --solver iterative --modes " +
                          std::to_string(modes) + " --json > " + json;
  if (std::system(cmd.c_str()) != 0) return r;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto& s = j.at("solver");
  const double a = s.at("assemble_s"), su = s.at("setup_s"), so = s.at("solve_s");
  r.values = {double(j.at("free_dofs")),   a, su, so, a + su + so, double(s.at("iterations")),
              double(s.at("max_residual"))};
  for (const auto& m : j.at("modes")) r.values.push_back(m.at("frequency_hz"));
  r.peak_rss_kb = static_cast<long>(double(s.at("peak_memory_bytes")) / 1024.0);
  r.ok = true;
  return r;
}

int iterative_study(const std::vector<std::string>& args) {
  std::vector<int> ks;
  bool direct = true;
  int ranks = 0;
  std::string hexfem = "hexfem";
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--no-direct")
      direct = false;
    else if (args[i] == "--ranks" && i + 1 < args.size())
      ranks = std::stoi(args[++i]);
    else if (args[i] == "--hexfem" && i + 1 < args.size())
      hexfem = args[++i];
    else
      ks.push_back(std::stoi(args[i]));
  }
  if (ks.empty()) ks = {14, 21, 32};
  const int modes = 10;
  std::printf(
      "| mesh (hex8) | DOF | path | assembly s | setup s | solve s | total s | peak MB | "
      "iterations | residual | load | f1 Hz "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int k : ks) {
    ChildResult res[3];
    const SolverChoice paths[2] = {SolverChoice::Direct, SolverChoice::Iterative};
    const std::string mpi_name = "iterative, " + std::to_string(ranks) + " ranks";
    const char* names[3] = {"direct", "iterative", mpi_name.c_str()};
    for (int p = direct ? 0 : 1; p < (ranks > 1 ? 3 : 2); ++p) {
      const std::string load = load_average();
      res[p] = p < 2 ? run_path(k, paths[p], modes) : run_mpi(k, ranks, hexfem, modes);
      const auto& v = res[p].values;
      if (!res[p].ok) {
        std::printf("| %dx%dx%d | | %s | failed | | | | %.0f | | | %s | |\n", 10 * k, k, k,
                    names[p], res[p].peak_rss_kb / 1024.0, load.c_str());
        continue;
      }
      std::printf(
          "| %dx%dx%d | %.0f | %s | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f | %.1e | %s | "
          "%.4f |\n",
          10 * k, k, k, v[0], names[p], v[1], v[2], v[3], v[4], res[p].peak_rss_kb / 1024.0, v[5],
          v[6], load.c_str(), v[7]);
      std::fflush(stdout);
    }
    for (int p = 1; p < 3; ++p) {
      if (!direct || !res[0].ok || !res[p].ok) continue;
      double diff = 0;
      for (int i = 0; i < modes; ++i)
        diff = std::max(diff, std::abs(res[p].values[7 + i] / res[0].values[7 + i] - 1));
      std::printf(
          "| | | **ratio direct / %s** | | | | **%.2f x** | **%.2f x** | | max rel. "
          "diff f1-f10 %.1e | | |\n",
          names[p], res[0].values[4] / res[p].values[4],
          double(res[0].peak_rss_kb) / double(res[p].peak_rss_kb), diff);
    }
  }
  return 0;
}

int write_cantilever(const std::vector<std::string>& args) {
  if (args.size() != 2) throw Error("usage: bench_modal write-mesh k file.msh");
  const int k = std::stoi(args[0]);
  write_mesh(make_box_mesh({100, 10, 10}, 10 * k, k, k, CellKind::Hex8), args[1]);
  return 0;
}

// ---------------------------------------------------------------------------------------------
ModalResult solve(const MixedMesh& mesh, const std::vector<std::string>& fix, int modes,
                  double scale, const Material& mat = kSteel) {
  ModalOptions o;
  o.material = mat;
  o.fix = fix;
  o.num_modes = modes;
  o.length_scale = scale;
  return solve_modal(mesh, o);
}

const char* kind_label(CellKind k) {
  return k == CellKind::Pyramid5 ? "pyramid+tet" : kind_name(k);
}

int ccx_study() {
  const MixedMesh hex = make_box_mesh({100, 10, 10}, 40, 4, 4, CellKind::Hex8);
  std::printf(
      "| kind (40x4x4 cubes) | ccx element | mode | hexfem Hz | ccx Hz | rel. diff "
      "|\n|---|---|---|---|---|---|\n");
  for (CellKind kind : {CellKind::Hex8, CellKind::Tet4, CellKind::Wedge6, CellKind::Pyramid5}) {
    const MixedMesh mesh = make_box_mesh({100, 10, 10}, 40, 4, 4, kind);
    const ModalResult r = solve(mesh, {"face:1"}, 6, 1e-3);
    const CcxRun ccx =
        run_ccx_frequency(mesh, select_fixed_dofs(mesh, {"face:1"}), kSteel, 6,
                          scratch(std::string("ccx_") + kind_name(kind)), "beam", 1e-3);
    const char* el = kind == CellKind::Hex8     ? "C3D8"
                     : kind == CellKind::Tet4   ? "C3D4"
                     : kind == CellKind::Wedge6 ? "C3D6"
                                                : "C3D4 + C3D8 (degenerate pyramids)";
    for (int i = 0; i < 6; ++i)
      std::printf("| %s | %s | %d | %.7g | %.7g | %.2e |\n", kind_label(kind), el, i + 1,
                  r.frequencies[i], ccx.output.frequencies[i],
                  r.frequencies[i] / ccx.output.frequencies[i] - 1);
  }
  return 0;
}

int convergence_study(const std::vector<std::string>& args) {
  std::vector<int> levels = {1, 2, 3, 4, 6, 8, 10};
  if (!args.empty()) {
    levels.clear();
    for (const auto& a : args) levels.push_back(std::stoi(a));
  }
  // 100 x 10 x 10 mm steel cantilever, 10m x m x m cubes; f1 = f2 (bending), f5 torsion, f6 axial.
  std::vector<std::vector<double>> hex;
  for (int m : levels) {
    const ModalResult r =
        solve(make_box_mesh({100, 10, 10}, 10 * m, m, m, CellKind::Hex8), {"face:1"}, 6, 1e-3);
    hex.push_back(r.frequencies);
  }
  const std::vector<double>& ref = hex.back();
  std::printf("Reference: hex8 at m = %d: f1 %.5g, f5 %.5g, f6 %.5g Hz\n\n", levels.back(), ref[0],
              ref[4], ref[5]);
  std::printf(
      "| kind | m (cubes 10m x m x m) | DOF | f1 Hz | f1 vs hex same m | f1 vs finest hex | f5 Hz "
      "(torsion) | f5 vs finest hex | f6 Hz (axial) | f6 vs finest hex |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (CellKind kind : {CellKind::Hex8, CellKind::Tet4, CellKind::Wedge6, CellKind::Pyramid5})
    for (std::size_t l = 0; l < levels.size(); ++l) {
      const int m = levels[l];
      const ModalResult r =
          solve(make_box_mesh({100, 10, 10}, 10 * m, m, m, kind), {"face:1"}, 6, 1e-3);
      const auto& f = r.frequencies;
      std::printf(
          "| %s | %d | %ld | %.2f | %+.2f%% | %+.2f%% | %.1f | %+.2f%% | %.1f | %+.2f%% |\n",
          kind_label(kind), m, r.num_free_dofs, f[0], 100 * (f[0] / hex[l][0] - 1),
          100 * (f[0] / ref[0] - 1), f[4], 100 * (f[4] / ref[4] - 1), f[5],
          100 * (f[5] / ref[5] - 1));
      std::fflush(stdout);
    }
  return 0;
}

int euler_study() {
  // Slender steel beam L = 1 m, 20 x 20 mm, clamped at x = 0.
  const double L = 1.0, h = 0.02;
  const double I = h * h * h * h / 12, A = h * h;
  const double fe =
      1.875104 * 1.875104 / (2 * M_PI * L * L) * std::sqrt(kSteel.E * I / (kSteel.rho * A));
  std::printf("Euler-Bernoulli f1 = %.5f Hz (L/h = %.0f)\n\n", fe, L / h);
  std::printf(
      "| hex8 mesh | elements through thickness | element aspect | DOF | f1 Hz | vs "
      "Euler-Bernoulli | solve s |\n|---|---|---|---|---|---|---|\n");
  for (int t : {2, 4, 6, 8})
    for (int aspect : {1, 2}) {
      const int nx = static_cast<int>(L / h) * t / aspect;
      const double t0 = now();
      const ModalResult r =
          solve(make_box_mesh({L, h, h}, nx, t, t, CellKind::Hex8), {"face:1"}, 1, 1.0);
      std::printf("| %dx%dx%d | %d | %d | %ld | %.4f | %+.3f%% | %.1f |\n", nx, t, t, t, aspect,
                  r.num_free_dofs, r.frequencies[0], 100 * (r.frequencies[0] / fe - 1), now() - t0);
      std::fflush(stdout);
    }
  return 0;
}

std::vector<std::string> fv52_fix() {
  // u_z = 0 along the four edges of the bottom face only.
  return {"z<1e-6&x<1e-6@z", "z<1e-6&x>9.999999@z", "z<1e-6&y<1e-6@z", "z<1e-6&y>9.999999@z"};
}

int fv52_study() {
  const Material mat{"fv52", 200e9, 0.3, 8000};
  const double ref[7] = {45.897, 109.44, 109.44, 167.89, 193.59, 206.19, 206.19};
  std::printf(
      "| hex8 mesh | DOF | f1-f3 (rigid) Hz | f4 | f5 | f6 | f7 | f8 | f9 | f10 | f4 vs 45.897 | "
      "max dev. f4-f10 | s |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::printf(
      "| NAFEMS reference | | 0 | 45.897 | 109.44 | 109.44 | 167.89 | 193.59 | 206.19 | 206.19 | | "
      "| |\n");
  for (auto [n, m] : {std::pair{10, 2},
                      {20, 2},
                      {20, 3},
                      {20, 4},
                      {30, 3},
                      {40, 4},
                      {40, 8},
                      {60, 6},
                      {60, 12}}) {
    const double t0 = now();
    const ModalResult r =
        solve(make_box_mesh({10, 10, 1}, n, n, m, CellKind::Hex8), fv52_fix(), 10, 1.0, mat);
    const auto& f = r.frequencies;
    double dev = 0;
    for (int i = 3; i < 10; ++i) dev = std::max(dev, std::abs(f[i] / ref[i - 3] - 1));
    std::printf("| %dx%dx%d | %ld | %.1e / %.1e / %.1e |", n, n, m, r.num_free_dofs, f[0], f[1],
                f[2]);
    for (int i = 3; i < 10; ++i) std::printf(" %.3f |", f[i]);
    std::printf(" %+.2f%% | %.2f%% | %.1f |\n", 100 * (f[3] / ref[0] - 1), 100 * dev, now() - t0);
    std::fflush(stdout);
  }
  return 0;
}

int nc_study(const std::vector<std::string>& args) {
  std::vector<int> levels = {1, 2, 4};
  if (!args.empty()) {
    levels.clear();
    for (const auto& a : args) levels.push_back(std::stoi(a));
  }
  std::printf(
      "| m | mesh | NC quad faces | DOF | f1 | f3 | f5 | f6 | max diff f1-f6 vs conformal "
      "|\n|---|---|---|---|---|---|---|---|---|\n");
  for (int m : levels) {
    const int nx = 10 * m, half = nx / 2;
    struct Variant {
      const char* name;
      std::function<CubeSpec(int, int, int)> spec;
    };
    const Variant variants[] = {
        {"conformal: pyramid layer (+x faces split) between hex and tet",
         [=](int i, int, int) {
           return i < half - 1    ? CubeSpec{CubeFill::Hex}
                  : i == half - 1 ? CubeSpec{CubeFill::Pyramids, 0b10}
                                  : CubeSpec{CubeFill::Tets};
         }},
        {"NC: hex next to two tets on each interface face",
         [=](int i, int, int) {
           return i < half ? CubeSpec{CubeFill::Hex} : CubeSpec{CubeFill::Tets};
         }},
        {"all hex8", [](int, int, int) { return CubeSpec{CubeFill::Hex}; }},
        {"all tet4", [](int, int, int) { return CubeSpec{CubeFill::Tets}; }},
    };
    std::vector<double> conf;
    for (const Variant& v : variants) {
      MixedMesh mesh = make_box_mesh({100, 10, 10}, nx, m, m, v.spec);
      flag_nonconformal_quads(mesh);
      const ModalResult r = solve(mesh, {"face:1"}, 6, 1e-3);
      const auto& f = r.frequencies;
      if (conf.empty()) conf = f;
      double diff = 0;
      for (int i = 0; i < 6; ++i) diff = std::max(diff, std::abs(f[i] / conf[i] - 1));
      std::printf("| %d | %s | %zu | %ld | %.2f | %.1f | %.1f | %.1f | %.3f%% |\n", m, v.name,
                  mesh.nc_cell.size(), r.num_free_dofs, f[0], f[2], f[4], f[5], 100 * diff);
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_modal benchmark|ccx|convergence|euler|fv52|nc [options]\n");
    return 2;
  }
  const std::string study = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  try {
    if (study == "benchmark") return benchmark(args);
    if (study == "ccx") return ccx_study();
    if (study == "iterative") return iterative_study(args);
    if (study == "write-mesh") return write_cantilever(args);
    if (study == "convergence") return convergence_study(args);
    if (study == "euler") return euler_study();
    if (study == "fv52") return fv52_study();
    if (study == "nc") return nc_study(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_modal: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr, "bench_modal: unknown study '%s'\n", study.c_str());
  return 2;
}
