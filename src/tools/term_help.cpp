#include "term_help.h"

#include "cvg_bench/core/diagnose/candidate_extensions.h"
#include "cvg_bench/core/model/model_term.h"
#include "cvg_bench/core/model/resonator_preset.h"

namespace cvg_bench {
namespace tools {
namespace {

/// `text` broken at spaces into lines of at most `width` characters, the first starting with
/// `first` spaces, the others with `rest`.
std::string wrapped(const std::string& text, size_t first, size_t rest, size_t width = 99) {
  std::string out, line(first, ' ');
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (line.size() + word.size() + 1 > width && line.find_first_not_of(' ') != std::string::npos) {
      out += line + "\n";
      line = std::string(rest, ' ');
    }
    line += (line.find_first_not_of(' ') == std::string::npos ? "" : " ") + word;
    start = end + 1;
  }
  return out + line + "\n";
}

std::string modesText(bool free_decay, bool forced) {
  if (free_decay && !forced) return " (free decay only)";
  if (forced && !free_decay) return " (forced only)";
  return "";
}

std::string modelTermLines(int indent) {
  const std::string pad(static_cast<size_t>(indent), ' ');
  std::string out;
  for (const auto& name : knownModelTermNames()) {
    const ModelTermPtr t = makeModelTerm(name);
    if (name != "linear" && name != "controls")  // the base, always in the model
      out += wrapped(name + ": " + t->description() +
                         modesText(t->appliesTo(ExperimentMode::kFreeDecay),
                                   t->appliesTo(ExperimentMode::kForced)),
                     pad.size(), pad.size() + 2);
    for (const auto& c : t->candidates())  // extensions that are no term of their own (mu)
      if (c.name != name)
        out += wrapped(c.name + ": " + c.cause + modesText(c.free_decay, c.forced) +
                           (c.needs_output_error ? ", needs --method ceres" : ""),
                       pad.size(), pad.size() + 2);
  }
  return out;
}

std::string candidateList(ExperimentMode mode) {
  std::string s;
  for (const auto& c : candidateExtensions(mode)) s += (s.empty() ? "" : ", ") + c.name;
  return s;
}

void replaceAll(std::string& s, const std::string& key, const std::string& value) {
  for (size_t at = s.find(key); at != std::string::npos; at = s.find(key, at + value.size()))
    s.replace(at, key.size(), value);
}

}  // namespace

std::string withTermLists(const std::string& help, int indent) {
  std::string s = help;
  replaceAll(s, "{MODEL_TERMS}\n", modelTermLines(indent));
  replaceAll(s, "{CANDIDATES_FREE_DECAY}", candidateList(ExperimentMode::kFreeDecay));
  replaceAll(s, "{CANDIDATES_FORCED}", candidateList(ExperimentMode::kForced));
  std::string effects;
  for (const auto& n : effectNames()) effects += (effects.empty() ? "" : " ") + n;
  replaceAll(s, "{EFFECT_NAMES}\n", wrapped(effects, 20, 20));
  return s;
}

}  // namespace tools
}  // namespace cvg_bench
