// Modal-solver study program: `bench_modal <study> [options]`, each study prints a Markdown table
// (validation/solver.md collects them).
//   benchmark [k ...] [--no-ccx] [--ccx-threads N]
//       10 modes of the 100x10x10 mm steel cantilever, hex8 (10k x k x k), clamped at x = 0:
//       wall time, peak memory (each run in its own child process, getrusage) and the same mesh
//       through CalculiX in the same run. Default k = 14 21 32 (~95k, ~306k, ~1.05M DOF).
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
#include <functional>
#include <string>
#include <vector>

#include "fem/boundary.hpp"
#include "fem/ccx_reference.hpp"
#include "fem/modal_solver.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/structured_box.hpp"

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
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--no-ccx")
      run_ccx = false;
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
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_modal: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr, "bench_modal: unknown study '%s'\n", study.c_str());
  return 2;
}
