// The model-term lists of the subcommands' help texts, made from the term registry (every
// ModelTerm's name, description, modes and candidacy), so that a registered term appears in
// every help without editing it.
#pragma once

#include <string>

namespace cvg_bench {
namespace tools {

/// `help` with its placeholders filled from the registry:
///   {MODEL_TERMS}     one line per extension of `--model` ("name: description (modes)"), each
///                     starting with `indent` spaces;
///   {CANDIDATES_FREE_DECAY}, {CANDIDATES_FORCED}  explain's candidates, comma-separated;
///   {EFFECT_NAMES}    lines of the names `simulate --effect` takes (parameters, drive, mu, eta),
///                     indented by 20.
std::string withTermLists(const std::string& help, int indent = 11);

}  // namespace tools
}  // namespace cvg_bench
