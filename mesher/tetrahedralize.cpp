#include "mesher/tetrahedralize.hpp"

#include <fcntl.h>
#include <malloc.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <tetgen.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "mesher/mesh/error.hpp"
#include "mesher/open_hash.hpp"

namespace hexfem {

namespace {

using Tri = std::array<std::int32_t, 3>;

Tri sorted_tri(std::int32_t a, std::int32_t b, std::int32_t c) {
  Tri t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

// The solid ids a CAD face bounds (one, or two for a face shared by touching solids).
std::vector<int> solids_of_face(const SurfaceMesh& surface, int face) {
  std::vector<int> ids;
  for (std::size_t s = 1; s < surface.faces_of_solid.size(); ++s)
    for (int f : surface.faces_of_solid[s])
      if (f == face) ids.push_back(static_cast<int>(s));
  return ids;
}

std::string intersection_message(const SurfaceMesh& surface, const SolidLocator& locator) {
  const auto pairs = locator.intersecting_triangles(3);
  if (pairs.empty()) return "";
  // Faces of two different solids that cross: the CAD's bodies overlap (an assembly's bolt in
  // its nut), which one conforming mesh cannot represent. Say so, not that the mesher failed.
  for (const auto& p : pairs) {
    const int fa = surface.mesh.bface_cad_face[p[0]], fb = surface.mesh.bface_cad_face[p[1]];
    const std::vector<int> sa = solids_of_face(surface, fa), sb = solids_of_face(surface, fb);
    if (sa.size() != 1 || sb.size() != 1 || sa[0] == sb[0]) continue;
    return "solids " + std::to_string(std::min(sa[0], sb[0])) + " and " +
           std::to_string(std::max(sa[0], sb[0])) +
           " of the CAD model touch or overlap (their faces " + std::to_string(fa) + " and " +
           std::to_string(fb) +
           " cross); add --glue to bond them where they touch, or mesh each solid on its own";
  }
  std::string msg = "the surface mesh intersects itself: ";
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (i) msg += "; ";
    msg += describe_surface_triangle(surface, pairs[i][0]) + " crosses " +
           describe_surface_triangle(surface, pairs[i][1]);
  }
  return msg;
}

// The CAD faces of the surface triangles that cross others (up to 64 crossing pairs).
std::vector<int> crossing_faces(const SurfaceMesh& surface, const SolidLocator& locator) {
  std::vector<int> faces;
  for (const auto& p : locator.intersecting_triangles(64))
    for (std::int32_t t : p) faces.push_back(surface.mesh.bface_cad_face[t]);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  if (!faces.empty() && faces.front() < 0) faces.erase(faces.begin());
  return faces;
}

// A read-only view of the child's output in shared memory, unmapped when it goes.
struct SharedOutput {
  void* base = MAP_FAILED;
  std::size_t bytes = 0;
  SharedOutput() = default;
  SharedOutput(const SharedOutput&) = delete;
  SharedOutput& operator=(const SharedOutput&) = delete;
  ~SharedOutput() {
    if (base != MAP_FAILED) ::munmap(base, bytes);
  }
};

// An array of n values in the shared output.
template <class T>
struct View {
  const T* data = nullptr;
  std::size_t n = 0;
  std::size_t size() const { return n; }
  const T& operator[](std::size_t i) const { return data[i]; }
};

// TetGen's output, read in place from the child's shared memory.
struct TetgenResult {
  std::string error;    // empty on success
  bool killed = false;  // by SIGKILL: the system's out-of-memory killer, not a fault of the input
  SharedOutput shared;
  View<double> points;
  View<int> tets, neighbors, trifaces;
  double seconds = 0;  // TetGen's steps in the child
  pid_t child = -1;    // on success: the child, still to be reaped (ChildReaper)
};

// Waits for a finished child (it may still be releasing its memory) when it goes out of scope.
struct ChildReaper {
  pid_t pid = -1;
  ~ChildReaper() {
    int status = 0;
    while (pid > 0 && ::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
};

// Writes all of `n` bytes (the pipe may take them in pieces).
bool write_all(int fd, const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

struct TriHash {
  std::size_t operator()(const Tri& t) const {
    return static_cast<std::size_t>(
        mix64(static_cast<std::uint64_t>(static_cast<std::uint32_t>(t[0])) << 32 |
              static_cast<std::uint32_t>(t[1])) ^
        mix64(static_cast<std::uint32_t>(t[2])));
  }
};

// The root of x's set in a union-find forest whose roots are their sets' least members,
// halving the path on the way (other threads may link or halve at the same time: every
// parent stays a member of the same set, never above its child).
std::int32_t find_root(std::vector<std::atomic<std::int32_t>>& parent, std::int32_t x) {
  for (;;) {
    std::int32_t p = parent[x].load(std::memory_order_relaxed);
    if (p == x) return x;
    const std::int32_t g = parent[p].load(std::memory_order_relaxed);
    if (g != p) parent[x].compare_exchange_weak(p, g, std::memory_order_relaxed);
    x = g;
  }
}

// Joins the sets of a and b, the larger root under the smaller: the roots that remain are the
// least tet of each set whatever the threads' order, so the regions do not depend on it.
void unite(std::vector<std::atomic<std::int32_t>>& parent, std::int32_t a, std::int32_t b) {
  for (;;) {
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    std::int32_t expected = a;
    if (parent[a].compare_exchange_strong(expected, b, std::memory_order_relaxed)) return;
  }
}

// The regions of TetGen's tets: sets joined across the faces that are not surface triangles,
// numbered in the order of their least tet; and per region its tet of largest volume (the
// least such tet on a tie). A union-find on both threads: a depth-first walk of the 6M tets of
// a million-vertex part took 0.8 s on one.
void tet_regions(View<int> tets, View<int> neighbors, const std::vector<double>& volume6,
                 const OpenHashSet<Tri, TriHash>& surface_tris, std::size_t num_surface_nodes,
                 std::vector<std::int32_t>& region, std::vector<std::size_t>& region_largest) {
  const std::size_t ntet = tets.size() / 4;
  const auto n = static_cast<std::ptrdiff_t>(ntet);
  std::vector<std::atomic<std::int32_t>> parent(ntet);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t t = 0; t < n; ++t)
    parent[t].store(static_cast<std::int32_t>(t), std::memory_order_relaxed);
  const auto s_nodes = static_cast<std::int32_t>(num_surface_nodes);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t t = 0; t < n; ++t) {
    for (int i = 0; i < 4; ++i) {
      const int nb = neighbors[4 * t + i];
      if (nb <= t) continue;  // each face once, and none on the hull
      // TetGen's neighbour i is across the face opposite corner i (its own vertex order).
      std::int32_t fv[3], k = 0;
      for (int a = 0; a < 4; ++a)
        if (a != i) fv[k++] = tets[4 * t + a];
      // Surface triangles (the output's boundary, equal to the input's) join surface nodes only.
      if (fv[0] < s_nodes && fv[1] < s_nodes && fv[2] < s_nodes &&
          surface_tris.contains(sorted_tri(fv[0], fv[1], fv[2])))
        continue;
      unite(parent, static_cast<std::int32_t>(t), nb);
    }
  }
  region.assign(ntet, -1);
  region_largest.clear();
  for (std::size_t t = 0; t < ntet; ++t) {
    const std::int32_t root = find_root(parent, static_cast<std::int32_t>(t));
    if (static_cast<std::size_t>(root) == t) {
      region[t] = static_cast<std::int32_t>(region_largest.size());
      region_largest.push_back(t);
    } else {
      region[t] = region[root];  // the root, the least tet of the set, came first
      std::size_t& best = region_largest[region[t]];
      if (volume6[t] > volume6[best]) best = t;
    }
  }
}

// Reads exactly `n` bytes; false at an early end of file or on an error.
bool read_all(int fd, void* data, std::size_t n) {
  char* p = static_cast<char*>(data);
  while (n > 0) {
    const ssize_t r = ::read(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r;
    n -= static_cast<std::size_t>(r);
  }
  return true;
}

// TetGen's own tetrahedralize() for the switches "pY...", step by step, so that its Delaunay
// recovery can be left out. That pass (run by 1.5.0 whenever -Y is given) queues every face of
// the mesh for Lawson flips to undo the few non-Delaunay faces the boundary recovery's flips
// left: 20 of TetGen's 36 s on ANC101 at 1M vertices, for a mesh that differs only next to the
// boundary (H_nbr 80.77 against 80.78 %, validation/volume.md). The steps and their order are
// those of tetrahedralize() in TetGen 1.5.0's tetgen.cxx.
// In the forked child only (run_tetgen_isolated), which ends with _exit: the mesh is never
// destroyed. On an error TetGen's terminatetetgen() frees its memory and throws; a destructor run
// by the unwinding would free it again, and glibc then aborts, or deadlocks on its own heap lock
// (seen on 40mm_capot: the parent waited for the child's message for ever).
// Returns the mesh, which the caller may delete once no error was thrown.
tetgenmesh* run_tetgen_stages(tetgenbehavior& b, tetgenio& in, tetgenio& out,
                              bool recover_delaunay) {
  tetgenmesh& m = *new tetgenmesh;  // NOLINT: on an error freed by the child's exit, see above
  m.b = &b;
  m.in = &in;
  m.addin = nullptr;
  m.initializepools();
  m.transfernodes();
  exactinit(b.verbose, b.noexact, b.nostaticfilter, m.xmax - m.xmin, m.ymax - m.ymin,
            m.zmax - m.zmin);
  clock_t split;  // TetGen's timing marks, unused here
  m.incrementaldelaunay(split);
  m.meshsurface();
  m.recoverboundary(split);
  m.carveholes();
  if (m.subvertstack->objects > 0l) m.suppresssteinerpoints();
  if (recover_delaunay) m.recoverdelaunay();
  if (!b.nojettison && (m.dupverts > 0 || m.unuverts > 0)) m.jettisonnodes();
  out.firstnumber = in.firstnumber;
  out.mesh_dim = in.mesh_dim;
  m.outnodes(&out);
  if (m.tetrahedrons->items > 0l) m.outelements(&out);
  if (m.subfaces->items > 0l) m.outsubfaces(&out);
  m.outneighbors(&out);
  return &m;
}

// The child's message through the pipe: the four array sizes, TetGen's seconds, then this mark (a
// child that died before leaves it out); the arrays are in the shared memory by then.
constexpr std::uint64_t kEndMark = 0x74657467656e4f4bull;
static_assert(std::is_same_v<REAL, double>, "TetGen built with REAL = double");

// Where the four arrays lie in the shared memory, one after the other (points as REAL, then tets,
// neighbours and boundary faces as int), from their value counts: the offsets, then the total.
std::array<std::size_t, 5> output_layout(const std::uint64_t sizes[4]) {
  std::array<std::size_t, 5> at{};
  at[1] = sizes[0] * sizeof(REAL);
  for (int a = 1; a < 4; ++a) at[a + 1] = at[a] + sizes[a] * sizeof(int);
  return at;
}

// Closes a file descriptor when it goes.
struct FdCloser {
  int fd = -1;
  ~FdCloser() {
    if (fd >= 0) ::close(fd);
  }
};

// Runs TetGen in a forked child. Debian's libtet 1.5.0 frees its memory twice when it reports an
// error (terminatetetgen() frees, then the unwinding destructor frees again) and segfaults, so
// an error inside TetGen cannot be caught in-process: the child keeps its mesh to its exit
// (run_tetgen_stages), and a crash of the child still becomes an Error here.
// The output comes back in shared memory, read where it lies; after a complete message the child
// is reaped later (its exit overlaps our work).
void run_tetgen_isolated(tetgenio& in, const char* switches, bool recover_delaunay,
                         TetgenResult& r) {
  // The arrays come back through shared memory (a pipe moved them at 150 MB/s here: 1.5 s at a
  // million vertices), their sizes and an end mark through the pipe.
  const FdCloser shm{::memfd_create("hexfem-tetgen", MFD_CLOEXEC)};
  if (shm.fd < 0) throw Error("TetGen: cannot create shared memory for its output");
  int fd[2];
  if (::pipe(fd) != 0) throw Error("TetGen: cannot create a pipe");
  ::fcntl(fd[1], F_SETPIPE_SZ, 1 << 20);  // fewer round trips; the default size works too
  std::fflush(stdout);
  const pid_t pid = ::fork();
  if (pid < 0) throw Error("TetGen: cannot fork");
  if (pid == 0) {
    ::close(fd[0]);
    // TetGen prints even with -Q on errors, and glibc reports the double free above on stderr
    // ("free(): invalid pointer") before the child dies: the parent says what went wrong.
    const int devnull = ::open("/dev/null", O_WRONLY);
    if (devnull >= 0) {
      ::dup2(devnull, STDOUT_FILENO);
      ::dup2(devnull, STDERR_FILENO);
    }
    int code = 0;
    double seconds = 0;
    tetgenio out;
    try {
      tetgenbehavior b;
      std::vector<char> sw(switches, switches + std::strlen(switches) + 1);
      if (!b.parse_commandline(sw.data())) ::_exit(90);
      const auto t0 = std::chrono::steady_clock::now();
      tetgenmesh* mesh = run_tetgen_stages(b, in, out, recover_delaunay);
      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      // Done without an error: the mesh and its memory go before the output is copied into
      // shared memory (the child's peak would otherwise grow by that copy).
      delete mesh;
      ::malloc_trim(0);
    } catch (int c) {
      code = c;
    }
    if (code != 0) ::_exit(100 + code);
    const std::uint64_t sizes[4] = {3ull * out.numberofpoints, 4ull * out.numberoftetrahedra,
                                    4ull * out.numberoftetrahedra, 3ull * out.numberoftrifaces};
    const std::array<std::size_t, 5> at = output_layout(sizes);
    if (::ftruncate(shm.fd, static_cast<off_t>(at[4])) != 0) ::_exit(92);
    if (at[4] > 0) {  // mmap refuses a length of 0
      void* to =
          ::mmap(nullptr, at[4], PROT_READ | PROT_WRITE, MAP_SHARED | MAP_POPULATE, shm.fd, 0);
      if (to == MAP_FAILED) ::_exit(92);
      // Each array is freed once copied, so that the child's peak memory grows by one array at
      // most (the child ends with _exit: tetgenio's destructor never runs).
      auto put = [&](auto*& array, int a) {
        if (at[a + 1] > at[a])
          std::memcpy(static_cast<char*>(to) + at[a], array, at[a + 1] - at[a]);
        delete[] array;
        array = nullptr;
      };
      put(out.pointlist, 0);
      put(out.tetrahedronlist, 1);
      put(out.neighborlist, 2);
      put(out.trifacelist, 3);
      ::munmap(to, at[4]);
    }
    const bool ok = write_all(fd[1], sizes, sizeof sizes) &&
                    write_all(fd[1], &seconds, sizeof seconds) &&
                    write_all(fd[1], &kEndMark, sizeof kEndMark);
    ::close(fd[1]);
    ::_exit(ok ? 0 : 91);
  }
  ::close(fd[1]);
  std::uint64_t sizes[4] = {0, 0, 0, 0}, mark = 0;
  bool complete = read_all(fd[0], sizes, sizeof sizes);
  // Sizes from a healthy child fit in memory; anything else is a broken message.
  for (const std::uint64_t n : sizes) complete = complete && n < (std::uint64_t{1} << 40);
  complete = complete && read_all(fd[0], &r.seconds, sizeof r.seconds) &&
             read_all(fd[0], &mark, sizeof mark) && mark == kEndMark;
  ::close(fd[0]);
  const std::array<std::size_t, 5> at = output_layout(sizes);
  if (complete) {
    struct stat st {};
    complete = ::fstat(shm.fd, &st) == 0 && static_cast<std::uint64_t>(st.st_size) == at[4];
    if (complete && at[4] > 0) {
      r.shared.base = ::mmap(nullptr, at[4], PROT_READ, MAP_SHARED | MAP_POPULATE, shm.fd, 0);
      r.shared.bytes = at[4];
      complete = r.shared.base != MAP_FAILED;
    }
  }
  if (complete) {
    const char* base = static_cast<const char*>(r.shared.base);
    r.points = {reinterpret_cast<const double*>(base + at[0]), sizes[0]};
    r.tets = {reinterpret_cast<const int*>(base + at[1]), sizes[1]};
    r.neighbors = {reinterpret_cast<const int*>(base + at[2]), sizes[2]};
    r.trifaces = {reinterpret_cast<const int*>(base + at[3]), sizes[3]};
    r.child = pid;
    return;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status)) {
    // SIGKILL is not a crash: the system's out-of-memory killer picks the largest process,
    // TetGen's child (ANC101 at 19.8M points: 20.2 GB of its own when killed).
    r.killed = WTERMSIG(status) == SIGKILL;
    r.error = "it crashed with signal " + std::to_string(WTERMSIG(status));
  } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.error = code == 103   ? "it found intersecting facets"
              : code == 101 ? "out of memory"
              : code > 100  ? "error code " + std::to_string(code - 100)
                            : "exit status " + std::to_string(code);
  } else {
    r.error = "its output was truncated";
  }
}

}  // namespace

TetMesh tetrahedralize(const SurfaceMesh& surface, const std::vector<Vec3>& interior_points,
                       const SolidLocator& locator, bool recover_delaunay) {
  const MixedMesh& sm = surface.mesh;
  const std::size_t ns = sm.nodes.size(), ni = interior_points.size(), nt = sm.num_bfaces();
  tetgenio in;
  // tetgenio frees its arrays with delete[]: allocate them with new[].
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(ns + ni);
  in.pointlist = new REAL[3 * (ns + ni)];
  for (std::size_t i = 0; i < ns + ni; ++i) {
    const Vec3& p = i < ns ? sm.nodes[i] : interior_points[i - ns];
    for (int a = 0; a < 3; ++a) in.pointlist[3 * i + a] = p[a];
  }
  in.numberoffacets = static_cast<int>(nt);
  in.facetlist = new tetgenio::facet[nt];
  in.facetmarkerlist = new int[nt];
  for (std::size_t t = 0; t < nt; ++t) {
    tetgenio::facet& f = in.facetlist[t];
    tetgenio::init(&f);
    f.numberofpolygons = 1;
    f.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&f.polygonlist[0]);
    f.polygonlist[0].numberofvertices = 3;
    f.polygonlist[0].vertexlist = new int[3];
    for (int i = 0; i < 3; ++i) f.polygonlist[0].vertexlist[i] = sm.bface(t)[i];
    in.facetmarkerlist[t] = static_cast<int>(t) + 1;
  }
  // p: PLC; Y: keep the boundary mesh; n: neighbours; z: 0-based; Q: quiet; O0: no flips or
  // smoothing after the Delaunay construction (they would break the lattice's cubes).
  TetgenResult out;
  run_tetgen_isolated(in, "pYnzQO0", recover_delaunay, out);
  const ChildReaper reaper{out.child};
  if (out.killed)
    throw Error(
        "TetGen was killed (signal 9), most likely by the system for lack of memory: "
        "use a larger h");
  if (!out.error.empty()) {
    const std::string why = intersection_message(surface, locator);
    if (why.starts_with("solids ")) throw CadError(why);  // a fault of the CAD, not of TetGen
    const std::string what = "TetGen failed (" + out.error + ")" +
                             (why.empty() ? std::string(" on the surface mesh") : ": " + why);
    if (why.empty()) throw Error(what);
    throw LocalMeshError(what, crossing_faces(surface, locator),
                         "a surface mesh that crossed itself");
  }
  TetMesh mesh;
  const std::size_t np = out.points.size() / 3;
  if (np < ns + ni) throw Error("TetGen dropped input points");
  mesh.steiner_points = np - ns - ni;
  mesh.tetgen_seconds = out.seconds;
  mesh.nodes.resize(np);
  for (std::size_t i = 0; i < np; ++i)
    mesh.nodes[i] = {out.points[3 * i], out.points[3 * i + 1], out.points[3 * i + 2]};
  for (std::size_t i = 0; i < ns + ni; ++i)
    mesh.nodes[i] = i < ns ? sm.nodes[i] : interior_points[i - ns];

  // The boundary must be the input triangles, each exactly once.
  std::vector<std::pair<Tri, std::int32_t>> input(nt);
  for (std::size_t t = 0; t < nt; ++t)
    input[t] = {sorted_tri(sm.bface(t)[0], sm.bface(t)[1], sm.bface(t)[2]),
                static_cast<std::int32_t>(t)};
  std::sort(input.begin(), input.end());
  std::vector<Tri> output(out.trifaces.size() / 3);
  for (std::size_t f = 0; f < output.size(); ++f)
    output[f] = sorted_tri(out.trifaces[3 * f], out.trifaces[3 * f + 1], out.trifaces[3 * f + 2]);
  std::sort(output.begin(), output.end());
  {
    std::size_t i = 0, j = 0;
    while (i < input.size() || j < output.size()) {
      if (j == output.size() || (i < input.size() && input[i].first < output[j])) {
        throw Error("TetGen did not keep surface " +
                    describe_surface_triangle(surface, input[i].second) +
                    (output.size() > nt ? " (it split the boundary)" : ""));
      }
      if (i == input.size() || output[j] < input[i].first)
        throw Error("TetGen created boundary face (" + std::to_string(output[j][0]) + ", " +
                    std::to_string(output[j][1]) + ", " + std::to_string(output[j][2]) +
                    ") that is not a surface triangle");
      ++i;
      ++j;
    }
  }

  OpenHashSet<Tri, TriHash> surface_tris(output.size());
  for (const Tri& t : output) surface_tris.insert(t);

  // Tets, positively oriented; then regions: flood fill across faces that are not surface
  // triangles, each region classified by the centroid of its largest tet (drops inner voids).
  // Not the first tet's: without the Delaunay recovery that may be a flat tet on a curved face,
  // its centroid on the wrong side of the chords (Torus_1, relaxed points: the solid dropped).
  const std::size_t ntet = out.tets.size() / 4;
  std::vector<std::array<std::int32_t, 4>> tets(ntet);
  std::vector<double> volume6(ntet);  // six times each tet's volume, once oriented
  const auto ntet_signed = static_cast<std::ptrdiff_t>(ntet);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t t = 0; t < ntet_signed; ++t) {
    auto& T = tets[t];
    for (int i = 0; i < 4; ++i) T[i] = out.tets[4 * t + i];
    const double o = orient(mesh.nodes[T[0]], mesh.nodes[T[1]], mesh.nodes[T[2]], mesh.nodes[T[3]]);
    if (o < 0) std::swap(T[2], T[3]);
    volume6[t] = std::abs(o);
  }
  std::vector<std::int32_t> region;
  std::vector<std::size_t> region_largest;  // per region: its tet of largest volume
  tet_regions(out.tets, out.neighbors, volume6, surface_tris, ns, region, region_largest);
  std::vector<int> region_solid(region_largest.size());
  for (std::size_t r = 0; r < region_largest.size(); ++r) {
    Vec3 c{0, 0, 0};
    for (int i = 0; i < 4; ++i)
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * mesh.nodes[tets[region_largest[r]][i]][a];
    region_solid[r] = locator.locate(c);
  }
  if (ntet > 0 &&
      std::none_of(region_solid.begin(), region_solid.end(), [](int s) { return s == 0; })) {
    // Every region inside (the usual case): the tets as they are, no copy.
    mesh.tet_solid.resize(ntet);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t t = 0; t < ntet_signed; ++t) mesh.tet_solid[t] = region_solid[region[t]];
    mesh.tets = std::move(tets);
    return mesh;
  }
  mesh.tets.reserve(ntet);
  mesh.tet_solid.reserve(ntet);
  for (std::size_t t = 0; t < ntet; ++t) {
    const int s = region_solid[region[t]];
    if (s == 0) {
      ++mesh.dropped_tets;
      continue;
    }
    mesh.tets.push_back(tets[t]);
    mesh.tet_solid.push_back(s);
  }
  if (mesh.tets.empty())
    throw Error("TetGen's tets all lie outside the solids (" + std::to_string(ntet) +
                " tets, none inside)");
  return mesh;
}

}  // namespace hexfem
