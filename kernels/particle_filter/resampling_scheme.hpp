#pragma once
// The resampling schemes of the particle filter, and their names.
#include <optional>
#include <string>

namespace kushner {

/// Douc, Cappe & Moulines (2005), "Comparison of resampling schemes for particle filtering": all four are
/// unbiased (expected offspring N w_j); systematic has the lowest variance in practice and is the default.
enum class ResamplingScheme { systematic, stratified, multinomial, residual };

inline const char* to_string(ResamplingScheme s) {
  switch (s) {
    case ResamplingScheme::systematic: return "systematic";
    case ResamplingScheme::stratified: return "stratified";
    case ResamplingScheme::multinomial: return "multinomial";
    case ResamplingScheme::residual: return "residual";
  }
  return "unknown";
}

/// The scheme called `name`, if there is one.
inline std::optional<ResamplingScheme> resampling_scheme_named(const std::string& name) {
  for (auto s : {ResamplingScheme::systematic, ResamplingScheme::stratified, ResamplingScheme::multinomial,
                 ResamplingScheme::residual})
    if (name == to_string(s)) return s;
  return std::nullopt;
}

}  // namespace kushner
