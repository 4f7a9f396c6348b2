// Entity numbers of a STEP file (ISO 10303-21, clause 6) checked on the text: OpenCASCADE's
// reader crashes on an entity number past 2^31 - 1, its translator on a reference to an entity
// the file does not define, and its shape healing on a coordinate near 1e20 (all found by the
// fuzz run, issue 14).
#include "mesher/cad/step_check.hpp"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <unordered_set>
#include <utility>
#include <vector>

namespace hexfem {

namespace {

// No coordinate, radius or parameter of a real part comes near this; OpenCASCADE's shape
// healing crashes on a point at 1e20 (fuzz run, seed 14, input 8633).
constexpr double kMaxNumber = 1e10;

bool word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.';
}

// The entity number after the '#' at i, its digits ending at `end`; past INT_MAX it stops
// growing (any value above INT_MAX says the same).
std::int64_t entity_number(std::string_view text, std::size_t i, std::size_t& end) {
  std::int64_t id = 0;
  for (end = i + 1; end < text.size() && std::isdigit(static_cast<unsigned char>(text[end])) != 0;
       ++end)
    if (id <= INT_MAX) id = id * 10 + (text[end] - '0');
  return id;
}

}  // namespace

std::string step_entity_problem(std::string_view text) {
  const std::size_t data = text.find("DATA;");
  if (data == std::string_view::npos) return "";
  // First, every '#' followed by digits, strings included: a quote that the file lost makes our
  // reading of strings differ from OpenCASCADE's, which then lexes an entity number that we
  // took for text (fuzz run, seed 15, input 3370: '#2147483648 =' after a broken string).
  for (std::size_t i = text.find('#', data); i != std::string_view::npos;
       i = text.find('#', i + 1)) {
    std::size_t j;
    if (entity_number(text, i, j) > INT_MAX)
      return "entity number " + std::string(text.substr(i, std::min<std::size_t>(j - i, 40))) +
             " is past 2147483647";
  }
  std::unordered_set<std::int64_t> defined;
  std::vector<std::pair<std::int64_t, std::int64_t>> references;  // (to, from)
  std::int64_t current = 0;  // the entity whose statement is being read
  bool statement_start = true;
  const std::size_t n = text.size();
  for (std::size_t i = data + 5; i < n; ++i) {
    const char c = text[i];
    if (c == '\'') {  // a string; '' inside is a quote, read as two strings
      const std::size_t end = text.find('\'', i + 1);
      if (end == std::string_view::npos) return "";  // unterminated: the reader says so
      i = end;
      statement_start = false;
      continue;
    }
    if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      const std::size_t end = text.find("*/", i + 2);
      if (end == std::string_view::npos) return "";
      i = end + 1;
      continue;
    }
    if (c == ';') {
      statement_start = true;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c)) != 0) continue;
    if (c != '#') {
      const bool starts_number = std::isdigit(static_cast<unsigned char>(c)) != 0 ||
                                 ((c == '-' || c == '+') && i + 1 < n &&
                                  std::isdigit(static_cast<unsigned char>(text[i + 1])) != 0);
      if (starts_number && !word_char(text[i - 1])) {
        std::size_t k = i + 1;
        while (k < n && k < i + 64 &&
               (std::isdigit(static_cast<unsigned char>(text[k])) != 0 || text[k] == '.' ||
                text[k] == 'E' || text[k] == 'e' || text[k] == '+' || text[k] == '-'))
          ++k;
        const std::string token(text.substr(i, k - i));
        const double v = std::strtod(token.c_str(), nullptr);
        if (!(std::abs(v) <= kMaxNumber))
          return "entity #" + std::to_string(current) + " holds the number " + token +
                 ", past any part's size (limit 1e10 in the file's units)";
        i = k - 1;
      }
      statement_start = false;
      continue;
    }
    std::size_t j;
    const std::int64_t id = entity_number(text, i, j);  // <= INT_MAX: checked above
    if (j == i + 1) return "'#' without an entity number";
    if (j < n && word_char(text[j])) {
      std::size_t k = j;
      while (k < n && k < j + 30 && word_char(text[k])) ++k;
      return "malformed entity number '" + std::string(text.substr(i, k - i)) + "'";
    }
    std::size_t k = j;
    while (k < n && std::isspace(static_cast<unsigned char>(text[k])) != 0) ++k;
    if (statement_start && k < n && text[k] == '=') {
      current = id;
      defined.insert(id);
    } else {
      references.emplace_back(id, current);
    }
    statement_start = false;
    i = j - 1;
  }
  for (const auto& [to, from] : references)
    if (defined.count(to) == 0)
      return "entity #" + std::to_string(from) + " refers to #" + std::to_string(to) +
             ", which the file does not define";
  return "";
}

}  // namespace hexfem
