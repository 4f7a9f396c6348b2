// The paper's Table 2 layout for `hexfem converge`: one row per mesh size, frequencies, errors
// against a reference, observed orders; written as text, CSV, Markdown and a log-log PNG plot.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hexfem {

struct ConvergenceRow {
  double h = 0;
  long nodes = 0, cells = 0;
  double h_vol = 0, h_nbr = 0;
  double seconds = 0;
  std::vector<double> frequencies;  // Hz
};

struct ConvergenceStudy {
  std::string part;
  std::vector<ConvergenceRow> rows;  // in the order run (coarse to fine)
  std::vector<double> reference;     // Hz; empty when there is none
  std::string reference_source;
  int num_frequencies() const;  // columns shown: min over rows (every mode asked for)
  // Relative error of row r, frequency i, against the reference (NaN without one).
  double error(std::size_t r, int i) const;
  // Rows r-1 and r have the same mesh: the same node and cell counts and every frequency within
  // 1e-9 (a size the curvature bound or the part's features set, not h; the coordinates may
  // differ in their last bits). Equal counts alone are not the same mesh (a cube at h = 4 and 3:
  // 27 cells each, f1 1.7e-4 apart).
  bool same_mesh(std::size_t r) const;
  // Observed order between rows r-1 and r: against the reference when there is one, else from
  // three consecutive rows (r-2, r-1, r). NaN when it cannot be computed, or when two of the
  // rows it reads have the same mesh.
  double observed_order(std::size_t r, int i) const;
  // True when every frequency moves in one direction from coarse to fine, towards the reference.
  bool monotone(int i) const;
};

// The order p of f(h) = f_inf + C h^p through three sizes h0 > h1 > h2 whose frequencies'
// successive differences have the ratio q = (f1 - f0) / (f2 - f1), any size ratios; negative when
// the differences grow. NaN when q <= 0 (the frequencies turn) or the sizes do not decrease.
double order_of_three_sizes(double h0, double h1, double h2, double q);

// Reads "reference_hz": [...] from a JSON file (validation/reference/*.json layout).
std::vector<double> read_reference_json(const std::filesystem::path& path);

std::string convergence_text(const ConvergenceStudy& s);
std::string convergence_markdown(const ConvergenceStudy& s);
std::string convergence_csv(const ConvergenceStudy& s);
// Writes <stem>.csv, <stem>.md and, with a reference, <stem>.png (gnuplot, log-log error vs h).
// Returns the files written. The plot is skipped with a note when gnuplot is absent.
std::vector<std::filesystem::path> write_convergence_files(const ConvergenceStudy& s,
                                                           const std::filesystem::path& stem);

}  // namespace hexfem
