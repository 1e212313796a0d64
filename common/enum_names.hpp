#pragma once
// Enum <-> name tables, one per enum, and the nearest known name for an unknown one. Header-only, so that
// filter/ (which builds alone with Eigen) can use it without linking stvl_common.
//
//   constexpr EnumName<Color> kColorNames[] = {{Color::kRed, "red"}, {Color::kGreen, "green"}};
//   Color c = parse_enum(text, kColorNames, "color");   // throws std::invalid_argument for unknown text
//   const char* name = enum_name(c, kColorNames);
#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace stvl {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

// Levenshtein distance (insertions, deletions, substitutions), for "did you mean" hints.
inline std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// The candidate closest to `text` when it is close enough to be a plausible typo (at most a third of its
// letters differ, and at least one matches), else "".
inline std::string nearest_name(const std::string& text, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = text.size() / 3 + 1;
  for (const auto& candidate : candidates) {
    const std::size_t d = edit_distance(text, candidate);
    if (d < best_distance && d < std::max(text.size(), candidate.size())) best = candidate, best_distance = d;
  }
  return best;
}

// "a, b, c": names joined for messages.
inline std::string joined(const std::vector<std::string>& names, const std::string& separator = ", ") {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : separator) + name;
  return text;
}

template <class E, std::size_t N>
const char* enum_name(E value, const EnumName<E> (&names)[N]) {
  for (const auto& n : names)
    if (n.value == value) return n.name;
  return "unknown";
}

// "a|b|c"
template <class E, std::size_t N>
std::string enum_choices(const EnumName<E> (&names)[N]) {
  std::string choices;
  for (const auto& n : names) choices += (choices.empty() ? "" : "|") + std::string(n.name);
  return choices;
}

// The enum named `text`; otherwise throws std::invalid_argument
// "unknown <what> 'txet' (expected a|b|c; did you mean 'text'?)".
template <class E, std::size_t N>
E parse_enum(const std::string& text, const EnumName<E> (&names)[N], const std::string& what) {
  for (const auto& n : names)
    if (text == n.name) return n.value;
  std::vector<std::string> candidates;
  for (const auto& n : names) candidates.emplace_back(n.name);
  const std::string hint = nearest_name(text, candidates);
  throw std::invalid_argument("unknown " + what + " '" + text + "' (expected " + enum_choices(names) +
                              (hint.empty() ? "" : "; did you mean '" + hint + "'?") + ")");
}

}  // namespace stvl
