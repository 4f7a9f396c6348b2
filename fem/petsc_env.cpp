#include "fem/petsc_env.hpp"

#include <dlfcn.h>
#include <slepcsys.h>
#include <sys/resource.h>

#include <climits>
#include <cstdlib>
#include <mutex>

#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

bool g_initialized = false;
std::string g_last_error;  // first message of the error being raised

// Records PETSc's own message instead of printing a traceback; petsc_check turns it into the
// one-line hexfem::Error.
PetscErrorCode record_error(MPI_Comm, int, const char* fun, const char*, PetscErrorCode n,
                            PetscErrorType p, const char* mess, void*) {
  if (p == PETSC_ERROR_INITIAL)
    g_last_error = std::string(mess ? mess : "error") + " (in " + (fun ? fun : "?") + ")";
  return n;
}

void finalize_at_exit() {
  if (g_initialized) SlepcFinalize();
  g_initialized = false;
}

}  // namespace

bool under_mpi_launcher() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}

void ensure_petsc() {
  static std::once_flag once;
  std::call_once(once, [] {
    int argc = 1;
    char name[] = "hexfem";
    char* args[] = {name, nullptr};
    char** argv = args;
    // No signal handler: a crash elsewhere in hexfem must not be reported as PETSc's.
    PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr);
    // Without mpirun, OpenMPI 4 starts a singleton by forking an `orted` helper for every run;
    // hexfem never spawns processes, so the isolated singleton (no helper) is enough. A user's
    // own setting wins; other MPIs ignore the variable.
    if (!under_mpi_launcher()) ::setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
    if (SlepcInitialize(&argc, &argv, nullptr, nullptr) != 0)
      throw Error("PETSc/SLEPc could not be initialized (MPI missing or misconfigured?)");
    g_initialized = true;
    PetscPushErrorHandler(record_error, nullptr);
    std::atexit(finalize_at_exit);
  });
}

int mpi_rank() {
  if (!g_initialized) return 0;
  int r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}

int mpi_size() {
  if (!g_initialized) return 1;
  int s = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  return s;
}

void petsc_check(PetscErrorCode code, const char* what) {
  if (code == 0) return;
  std::string msg = g_last_error.empty() ? "code " + std::to_string(code) : g_last_error;
  g_last_error.clear();
  for (char& c : msg)
    if (c == '\n') c = ' ';
  throw Error(std::string(what) + ": PETSc error: " + msg);
}

double peak_rss_bytes() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return 1024.0 * static_cast<double>(ru.ru_maxrss);
}

namespace {

using SetThreads = void (*)(int);
using GetThreads = int (*)();

// OpenBLAS's thread calls, looked up at run time: Debian's libblas.so.3 may be another BLAS.
SetThreads openblas_set() {
  return reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
}

}  // namespace

SingleThreadedBlas::SingleThreadedBlas() {
  const auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  const SetThreads set = openblas_set();
  if (!get || !set || get() <= 1) return;
  old_threads_ = get();
  set(1);
}

SingleThreadedBlas::~SingleThreadedBlas() {
  if (old_threads_ > 0) openblas_set()(old_threads_);
}

void broadcast_bytes(void* data, long bytes) {
  if (mpi_size() == 1) return;
  char* p = static_cast<char*>(data);
  while (bytes > 0) {  // MPI counts are int
    const int chunk = static_cast<int>(std::min<long>(bytes, INT_MAX / 2));
    MPI_Bcast(p, chunk, MPI_BYTE, 0, PETSC_COMM_WORLD);
    p += chunk;
    bytes -= chunk;
  }
}

}  // namespace hexfem
