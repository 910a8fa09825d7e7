// Error types of the core. Bad input (files, options, parameters) is an InputError; an analysis
// that ran but cannot give an answer (rank deficiency, no convergence) is an AnalysisError. The
// offline tool maps them to exit status 2 and 1; nodes turn them into success=false with the
// message.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace cvg_bench {

class InputError : public std::invalid_argument {
 public:
  explicit InputError(const std::string& what) : std::invalid_argument(what) {}
};

class AnalysisError : public std::runtime_error {
 public:
  explicit AnalysisError(const std::string& what) : std::runtime_error(what) {}
};

/// Throws InputError("<what> must be finite, got <v>") unless v is finite.
void requireFinite(double v, const std::string& what);
/// Throws InputError unless v is finite and > 0.
void requirePositive(double v, const std::string& what);
/// Throws InputError("<what>: <problem 1>; <problem 2>; ...") unless problems is empty (the list an
/// Options::validate() returns).
void throwIfInvalid(const std::string& what, const std::vector<std::string>& problems);

}  // namespace cvg_bench
