// The PETSc/SLEPc runtime of the iterative eigensolver (iterative_solver.hpp): initialized once
// per process, lazily for a plain run (MPI as a singleton) or at start under an MPI launcher,
// and PETSc error codes turned into hexfem::Error.
#pragma once

#include <petscsys.h>

#include <string>
#include <vector>

namespace hexfem {

// True when this process was started by mpirun/mpiexec (OpenMPI, MPICH or PMI environment).
bool under_mpi_launcher();

// Initializes SLEPc (and PETSc, MPI) once; later calls do nothing. PETSc reads options only
// from the PETSC_OPTIONS environment variable (never from hexfem's command line), so a run can
// be tuned without rebuilding. Finalized at exit.
void ensure_petsc();

int mpi_rank();  // 0 without MPI
int mpi_size();  // 1 without MPI

// Throws hexfem::Error("<what>: PETSc error: <message>") when `code` is non-zero.
void petsc_check(PetscErrorCode code, const char* what);
#define HEXFEM_PETSC(call) ::hexfem::petsc_check((call), #call)

// One BLAS thread for the guard's life, then the old count back. OpenBLAS's own threads spin
// between calls and fight the V-cycle's OpenMP threads for the cores: on the steel part at h 1
// (one process, two cores) the eigensolver took 20.2 s with 9.4 s of system time, 16.6 s with
// one BLAS thread. Under mpirun each rank is bound to a core and OpenBLAS already uses one. Does
// nothing with a BLAS that has no openblas_set_num_threads.
class SingleThreadedBlas {
 public:
  SingleThreadedBlas();
  ~SingleThreadedBlas();
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

 private:
  int old_threads_ = 0;  // 0: nothing to restore
};

// Peak resident memory of this process [bytes] (getrusage).
double peak_rss_bytes();

// Broadcast helpers over PETSC_COMM_WORLD from rank 0 (the vector is resized on the others).
template <class T>
void broadcast_vector(std::vector<T>& v);
void broadcast_bytes(void* data, long bytes);

template <class T>
void broadcast_vector(std::vector<T>& v) {
  long n = static_cast<long>(v.size());
  broadcast_bytes(&n, sizeof n);
  v.resize(n);
  broadcast_bytes(v.data(), n * static_cast<long>(sizeof(T)));
}

}  // namespace hexfem
