#include "app/convergence_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string fmt(const char* f, double v) {
  if (std::isnan(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
}  // namespace

int ConvergenceStudy::num_frequencies() const {
  std::size_t n = 6;
  for (const auto& r : rows) n = std::min(n, r.frequencies.size());
  return rows.empty() ? 0 : static_cast<int>(n);
}

double ConvergenceStudy::error(std::size_t r, int i) const {
  if (static_cast<std::size_t>(i) >= reference.size()) return kNaN;
  return (rows[r].frequencies[i] - reference[i]) / reference[i];
}

double ConvergenceStudy::observed_order(std::size_t r, int i) const {
  if (r == 0) return kNaN;
  const double ratio = std::log(rows[r - 1].h / rows[r].h);
  if (!reference.empty()) {
    const double e0 = std::abs(error(r - 1, i)), e1 = std::abs(error(r, i));
    if (!(e0 > 0 && e1 > 0)) return kNaN;
    return std::log(e0 / e1) / ratio;
  }
  if (r < 2) return kNaN;
  const double d0 = std::abs(rows[r - 1].frequencies[i] - rows[r - 2].frequencies[i]);
  const double d1 = std::abs(rows[r].frequencies[i] - rows[r - 1].frequencies[i]);
  if (!(d0 > 0 && d1 > 0)) return kNaN;
  return std::log(d0 / d1) / ratio;
}

bool ConvergenceStudy::monotone(int i) const {
  for (std::size_t r = 1; r < rows.size(); ++r) {
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
  out += "observed order (last pair):";
  for (int i = 0; i < nf; ++i)
    out += " f" + std::to_string(i + 1) + " " + fmt("%.2f", s.observed_order(s.rows.size() - 1, i));
  out += "\nmonotone:";
  for (int i = 0; i < nf; ++i)
    out += std::string(" f") + std::to_string(i + 1) + (s.monotone(i) ? " yes" : " no");
  out += "\n";
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
  out += "\nObserved order (finest pair):";
  for (int i = 0; i < nf; ++i)
    out += " f" + std::to_string(i + 1) + " " +
           fmt("%.2f", s.observed_order(s.rows.size() - 1, i)) + ";";
  out += "\n";
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
    out += fmt("%.17g", row.h) + "," + std::to_string(row.nodes) + "," + std::to_string(row.cells) +
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
  const std::filesystem::path data = stem.string() + ".plot.dat";
  const std::filesystem::path png = stem.string() + ".png";
  const int nf = std::min(s.num_frequencies(), 4);
  std::string dat;
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    dat += fmt("%.17g", s.rows[r].h);
    for (int i = 0; i < nf; ++i) dat += fmt(" %.6e", std::abs(s.error(r, i)));
    dat += "\n";
  }
  write_atomically(data, false, [&](std::ostream& o) { o << dat; });
  std::string script = "set terminal pngcairo noenhanced size 800,600\nset output '" +
                       png.string() +
                       ".tmp'\n"
                       "set logscale xy\nset xlabel 'h'\nset ylabel '|f - f_ref| / f_ref'\n"
                       "set grid\nset key left top\nset title 'hexfem converge: " +
                       s.part + "'\nplot ";
  for (int i = 0; i < nf; ++i)
    script += std::string(i ? ", " : "") + "'" + data.string() +
              "' using 1:" + std::to_string(i + 2) + " with linespoints title 'f" +
              std::to_string(i + 1) + "'";
  script += "\n";
  const std::filesystem::path gp = stem.string() + ".plot.gp";
  write_atomically(gp, false, [&](std::ostream& o) { o << script; });
  const int rc = std::system(("gnuplot '" + gp.string() + "' 2>/dev/null").c_str());
  if (rc == 0 && std::filesystem::exists(png.string() + ".tmp")) {
    std::filesystem::rename(png.string() + ".tmp", png);
    written.push_back(png);
  } else {
    std::fprintf(stderr, "hexfem: note: gnuplot failed or is absent; no plot written\n");
  }
  std::filesystem::remove(gp);
  std::filesystem::remove(data);
  return written;
}

}  // namespace hexfem
