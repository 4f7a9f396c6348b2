#include "app/convergence_table.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Runs `program` (found on PATH) with `input` on its stdin and returns its stdout; empty when
// it cannot be started or fails. stderr goes nowhere. The input is written whole before the
// output is read: it must fit a pipe's buffer (64 KiB), as a plot script does.
std::string run_filter(const char* program, const std::string& input) {
  if (input.size() > 60000) return {};
  int in[2], out[2];
  if (::pipe2(in, O_CLOEXEC) != 0) return {};
  if (::pipe2(out, O_CLOEXEC) != 0) {
    ::close(in[0]);
    ::close(in[1]);
    return {};
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in[0], 0);
  posix_spawn_file_actions_adddup2(&actions, out[1], 1);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  char* argv[] = {const_cast<char*>(program), nullptr};
  pid_t pid = -1;
  const int spawned = ::posix_spawnp(&pid, program, &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(in[0]);
  ::close(out[1]);
  std::string result;
  // A filter that exits before reading all of its input must not kill us with SIGPIPE.
  const auto old_pipe = std::signal(SIGPIPE, SIG_IGN);
  if (spawned == 0) {
    for (std::size_t done = 0; done < input.size();) {
      const ssize_t n = ::write(in[1], input.data() + done, input.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
  }
  ::close(in[1]);
  std::signal(SIGPIPE, old_pipe);
  if (spawned == 0) {
    char buf[1 << 16];
    for (;;) {
      const ssize_t n = ::read(out[0], buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      result.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(out[0]);
  int status = 0;
  if (spawned != 0 || ::waitpid(pid, &status, 0) != pid || !WIFEXITED(status) ||
      WEXITSTATUS(status) != 0)
    return {};
  return result;
}

std::string fmt(const char* f, double v) {
  if (std::isnan(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// A line naming each size that gave the same mesh as the size before, or nothing.
std::string same_mesh_note(const ConvergenceStudy& s) {
  std::string out;
  for (std::size_t r = 1; r < s.rows.size(); ++r) {
    if (!s.same_mesh(r)) continue;
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "h = %g gave the same mesh as h = %g (%ld nodes: a size the part's curvature or "
                  "features set): no order from it\n",
                  s.rows[r].h, s.rows[r - 1].h, s.rows[r].nodes);
    out += buf;
  }
  return out;
}

// What the observed order is read from.
std::string order_basis(const ConvergenceStudy& s) {
  return s.reference.empty() ? "the last three sizes" : "the last two sizes' errors";
}

// A negative order: the differences (or errors) grow from one size to the next, so the sizes
// are not yet where the error goes as h^p (a clamp rim or a re-entrant edge, whose singular
// field the uniform sizes do not resolve: gehause_rohteil at h = 5.6, 2.8, 1.4 read -1.5).
std::string growing_note(const ConvergenceStudy& s) {
  std::string modes;
  for (int i = 0; i < s.num_frequencies(); ++i)
    if (s.observed_order(s.rows.size() - 1, i) < 0) modes += " f" + std::to_string(i + 1);
  if (modes.empty()) return "";
  return "note:" + modes + ": the " +
         (s.reference.empty() ? std::string("differences") : std::string("errors")) +
         " grow from one size to the next (order < 0): these sizes are not yet in the "
         "asymptotic range; refine further, or grade the singular edges (--singular-size)\n";
}

}  // namespace

int ConvergenceStudy::num_frequencies() const {
  std::size_t n = rows.empty() ? 0 : rows.front().frequencies.size();
  for (const auto& r : rows) n = std::min(n, r.frequencies.size());
  return rows.empty() ? 0 : static_cast<int>(n);
}

double ConvergenceStudy::error(std::size_t r, int i) const {
  if (static_cast<std::size_t>(i) >= reference.size()) return kNaN;
  return (rows[r].frequencies[i] - reference[i]) / reference[i];
}

// Frequencies of one mesh solved twice differ by the solver's rounding, far below this.
constexpr double kSameFrequency = 1e-9;

bool ConvergenceStudy::same_mesh(std::size_t r) const {
  if (!(r > 0 && r < rows.size() && rows[r].nodes > 0 && rows[r].nodes == rows[r - 1].nodes &&
        rows[r].cells == rows[r - 1].cells))
    return false;
  const std::vector<double>&a = rows[r - 1].frequencies, &b = rows[r].frequencies;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    if (!(std::abs(b[i] - a[i]) <= kSameFrequency * std::abs(a[i]))) return false;
  return true;
}

double order_of_three_sizes(double h0, double h1, double h2, double q) {
  if (!(q > 0) || !(h0 > h1 && h1 > h2 && h2 > 0)) return kNaN;
  const double l0 = std::log(h0 / h1), l2 = std::log(h2 / h1);
  // g(p) = (h0^p - h1^p) / (h1^p - h2^p), over h1^p; expm1 keeps small p exact. g rises from 0
  // (p -> -inf) to inf, through l0 / -l2 at p = 0: one root, found by bisection.
  auto g = [&](double p) {
    return std::abs(p) < 1e-12 ? l0 / -l2 : std::expm1(p * l0) / -std::expm1(p * l2);
  };
  double lo = -30, hi = 30;
  if (!(g(lo) < q && q < g(hi))) return kNaN;
  for (int k = 0; k < 200 && hi - lo > 1e-14; ++k) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) < q ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double ConvergenceStudy::observed_order(std::size_t r, int i) const {
  if (r == 0 || same_mesh(r)) return kNaN;
  if (!reference.empty()) {
    const double e0 = std::abs(error(r - 1, i)), e1 = std::abs(error(r, i));
    if (!(e0 > 0 && e1 > 0)) return kNaN;
    return std::log(e0 / e1) / std::log(rows[r - 1].h / rows[r].h);
  }
  if (r < 2 || same_mesh(r - 1)) return kNaN;
  // Sizes in any ratio: log(d0 / d1) / log(ratio) holds only when h0 / h1 = h1 / h2 (the cube
  // at h = 5, 3.33, 2.5 read 3.64 for 1.99).
  const double d0 = rows[r - 1].frequencies[i] - rows[r - 2].frequencies[i];
  const double d1 = rows[r].frequencies[i] - rows[r - 1].frequencies[i];
  if (!(d0 != 0 && d1 != 0)) return kNaN;
  return order_of_three_sizes(rows[r - 2].h, rows[r - 1].h, rows[r].h, d0 / d1);
}

bool ConvergenceStudy::monotone(int i) const {
  for (std::size_t r = 1; r < rows.size(); ++r) {
    if (same_mesh(r) || (reference.empty() && same_mesh(r - 1))) continue;
    if (!reference.empty()) {
      if (std::abs(error(r, i)) > std::abs(error(r - 1, i))) return false;
    } else if (r >= 2) {
      const double a = rows[r - 1].frequencies[i] - rows[r - 2].frequencies[i];
      const double b = rows[r].frequencies[i] - rows[r - 1].frequencies[i];
      if (a * b < 0) return false;
    }
  }
  return true;
}

std::vector<double> read_reference_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read reference '" + path.string() + "'");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception&) {
    throw Error("reference '" + path.string() + "' is not valid JSON");
  }
  if (!j.is_object() || !j.contains("reference_hz") || !j["reference_hz"].is_array())
    throw Error("reference '" + path.string() + "' has no \"reference_hz\" array");
  std::vector<double> hz;
  for (const nlohmann::json& f : j["reference_hz"]) {
    // Checked here: nlohmann's own messages ("[json.exception.type_error.302] ...") mean
    // nothing to a user.
    if (!f.is_number() || !std::isfinite(f.get<double>()) || !(f.get<double>() > 0))
      throw Error("reference '" + path.string() +
                  "': \"reference_hz\" must hold positive "
                  "numbers (found " +
                  f.dump() + ")");
    hz.push_back(f.get<double>());
  }
  return hz;
}

std::string convergence_text(const ConvergenceStudy& s) {
  const int nf = s.num_frequencies();
  std::string out = "h        nodes     cells     H_vol %  ";
  for (int i = 0; i < nf; ++i)
    out += fmt("f%-11.0f", i + 1) + (s.reference.empty() ? "" : "err %     ");
  out += "\n";
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    const auto& row = s.rows[r];
    char buf[128];
    std::snprintf(buf, sizeof buf, "%-8g %-9ld %-9ld %-8.2f ", row.h, row.nodes, row.cells,
                  row.h_vol);
    out += buf;
    for (int i = 0; i < nf; ++i) {
      out += fmt("%-12.2f", row.frequencies[i]);
      if (!s.reference.empty()) out += fmt("%+-10.3f", 100 * s.error(r, i));
    }
    out += "\n";
  }
  if (!s.reference.empty()) {
    out += "reference                            ";
    for (int i = 0; i < nf && i < static_cast<int>(s.reference.size()); ++i)
      out += fmt("%-12.2f", s.reference[i]) + "          ";
    out += "(" + s.reference_source + ")\n";
  }
  out += same_mesh_note(s);
  out += "observed order (" + order_basis(s) + "):";
  for (int i = 0; i < nf; ++i)
    out += " f" + std::to_string(i + 1) + " " + fmt("%.2f", s.observed_order(s.rows.size() - 1, i));
  out += "\nmonotone:";
  for (int i = 0; i < nf; ++i)
    out += std::string(" f") + std::to_string(i + 1) + (s.monotone(i) ? " yes" : " no");
  out += "\n" + growing_note(s);
  return out;
}

std::string convergence_markdown(const ConvergenceStudy& s) {
  const int nf = s.num_frequencies();
  std::string out = "| h | nodes | cells | H_vol % |";
  std::string rule = "|---:|---:|---:|---:|";
  for (int i = 0; i < nf; ++i) {
    out += " f" + std::to_string(i + 1) + " (Hz) |";
    rule += "---:|";
    if (!s.reference.empty()) {
      out += " err f" + std::to_string(i + 1) + " |";
      rule += "---:|";
    }
  }
  out += "\n" + rule + "\n";
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    const auto& row = s.rows[r];
    out += "| " + fmt("%g", row.h) + " | " + std::to_string(row.nodes) + " | " +
           std::to_string(row.cells) + " | " + fmt("%.2f", row.h_vol) + " |";
    for (int i = 0; i < nf; ++i) {
      out += fmt(" %.2f |", row.frequencies[i]);
      if (!s.reference.empty()) out += fmt(" %+.3f %% |", 100 * s.error(r, i));
    }
    out += "\n";
  }
  if (!s.reference.empty()) {
    out += "| reference | | | |";
    for (int i = 0; i < nf; ++i)
      out += i < static_cast<int>(s.reference.size()) ? fmt(" %.2f | |", s.reference[i]) : " - | |";
    out += "\n\nReference: " + s.reference_source + "\n";
  }
  out += "\n" + same_mesh_note(s);
  out += "Observed order (" + order_basis(s) + "):";
  for (int i = 0; i < nf; ++i)
    out += " f" + std::to_string(i + 1) + " " +
           fmt("%.2f", s.observed_order(s.rows.size() - 1, i)) + ";";
  out += "\n";
  if (const std::string note = growing_note(s); !note.empty()) out += "\n" + note;
  return out;
}

std::string convergence_csv(const ConvergenceStudy& s) {
  const int nf = s.num_frequencies();
  std::string out = "h,nodes,cells,H_nbr,H_vol,seconds";
  for (int i = 0; i < nf; ++i)
    out += ",f" + std::to_string(i + 1) +
           (s.reference.empty() ? "" : ",err_f" + std::to_string(i + 1));
  out += "\n";
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    const auto& row = s.rows[r];
    out += fmt("%.15g", row.h) + "," + std::to_string(row.nodes) + "," + std::to_string(row.cells) +
           "," + fmt("%.4f", row.h_nbr) + "," + fmt("%.4f", row.h_vol) + "," +
           fmt("%.3f", row.seconds);
    for (int i = 0; i < nf; ++i) {
      out += fmt(",%.6f", row.frequencies[i]);
      if (!s.reference.empty()) out += fmt(",%.6e", s.error(r, i));
    }
    out += "\n";
  }
  return out;
}

std::vector<std::filesystem::path> write_convergence_files(const ConvergenceStudy& s,
                                                           const std::filesystem::path& stem) {
  std::vector<std::filesystem::path> written;
  auto write = [&](const std::string& ext, const std::string& text) {
    const std::filesystem::path p = stem.string() + ext;
    write_atomically(p, false, [&](std::ostream& o) { o << text; });
    written.push_back(p);
  };
  write(".csv", convergence_csv(s));
  write(".md", "# Convergence of " + s.part + "\n\n" + convergence_markdown(s));
  if (s.reference.empty() || s.rows.size() < 2) return written;

  // Plot |error| vs h, log-log, one line per frequency, with gnuplot (Debian's gnuplot-nox).
  // The data go in the script (a datablock) and the PNG comes back on gnuplot's stdout: no
  // file of gnuplot's own, so nothing is left behind under a guessable name on a signal.
  const std::filesystem::path png = stem.string() + ".png";
  const int nf = std::min(s.num_frequencies(), 4);
  std::string script = "$errors << EOD\n";
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    script += fmt("%.17g", s.rows[r].h);
    for (int i = 0; i < nf; ++i) script += fmt(" %.6e", std::abs(s.error(r, i)));
    script += "\n";
  }
  script +=
      "EOD\nset terminal pngcairo noenhanced size 800,600\n"
      "set logscale xy\nset xlabel 'h'\nset ylabel '|f - f_ref| / f_ref'\n"
      "set grid\nset key left top\nset title 'hexfem converge: " +
      s.part + "'\nplot ";
  for (int i = 0; i < nf; ++i)
    script += std::string(i ? ", " : "") + "$errors using 1:" + std::to_string(i + 2) +
              " with linespoints title 'f" + std::to_string(i + 1) + "'";
  script += "\n";
  const std::string image = run_filter("gnuplot", script);
  if (image.rfind("\x89PNG", 0) == 0) {
    write_atomically(png, true, [&](std::ostream& o) { o << image; });
    written.push_back(png);
  } else {
    std::fprintf(stderr, "hexfem: note: gnuplot failed or is absent; no plot written\n");
  }
  return written;
}

}  // namespace hexfem
