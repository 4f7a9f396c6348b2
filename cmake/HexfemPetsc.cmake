# PETSc + SLEPc (the iterative eigensolver, fem/iterative_solver.cpp) and the MPI they are built
# with, found through their pkg-config files. Required: a missing one stops configure naming the
# Debian package.
find_package(PkgConfig QUIET)
hexfem_require(PKG_CONFIG_FOUND pkg-config)
pkg_check_modules(HEXFEM_PETSC QUIET IMPORTED_TARGET PETSc)
hexfem_require(HEXFEM_PETSC_FOUND petsc-dev)
pkg_check_modules(HEXFEM_SLEPC QUIET IMPORTED_TARGET SLEPc)
hexfem_require(HEXFEM_SLEPC_FOUND libslepc-real-dev)
find_package(MPI QUIET COMPONENTS C)
hexfem_require(MPI_C_FOUND "libopenmpi-dev openmpi-bin")
# The BLAS PETSc calls (libblas.so.3, OpenBLAS through Debian's alternatives): fem/lobpcg.cpp
# calls dgemm itself, through petscblaslapack.h.
find_package(BLAS QUIET)
hexfem_require(BLAS_FOUND libblas-dev)
find_program(HEXFEM_MPIEXEC NAMES mpirun mpiexec)
hexfem_require(HEXFEM_MPIEXEC openmpi-bin)

add_library(hexfem_petsc INTERFACE)
target_link_libraries(hexfem_petsc INTERFACE PkgConfig::HEXFEM_SLEPC PkgConfig::HEXFEM_PETSC
                                             MPI::MPI_C BLAS::BLAS)
