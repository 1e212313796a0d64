// stvl-bench compare A B [--fail-on RULE ...]: two runs side by side, every figure with its delta; exit 1 when a
// rule finds a regression (a CI gate), 2 for a run without metrics.json or a rule that does not parse.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "analysis/compare.hpp"
#include "common/atomic_file.hpp"
#include "tools/command.hpp"

namespace stvl::tools {
using namespace stvl::analysis;
namespace {

struct CompareOptions {
  std::string a, b;
  std::vector<std::string> fail_on;
  bool no_default_rules = false;
  std::string markdown, html, junit;
};

int compare(const CompareOptions& o) {
  const nlohmann::json a = load_metrics(o.a), b = load_metrics(o.b);
  if (is_replay(a) != is_replay(b))
    throw std::invalid_argument((is_replay(a) ? o.a : o.b) + " is a replay of a recording and " +
                                (is_replay(a) ? o.b : o.a) + " a simulated run: compare two runs or two replays");
  std::vector<CompareRule> rules =
      o.no_default_rules ? std::vector<CompareRule>{} : default_compare_rules(!is_replay(a));
  for (const auto& text : o.fail_on) rules.push_back(parse_compare_rule(text));
  const Comparison c = compare_metrics(a, b, rules, o.a, o.b);
  const std::string markdown = comparison_markdown(c);
  std::printf("%s", markdown.c_str());
  if (!o.markdown.empty()) write_file_atomically(o.markdown, markdown);
  if (!o.html.empty()) write_file_atomically(o.html, comparison_html(c));
  if (!o.junit.empty()) write_file_atomically(o.junit, comparison_junit(c));
  return c.regressed() ? kExitCheckFailed : kExitOk;
}

const CommandRegistration kCompare("compare", [](CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto* cmd = app.add_subcommand("compare", "Compare two runs (folders or metrics.json files); exit 1 on a regression");
  cmd->add_option("a", o->a, "The reference run: a run folder or its metrics.json")->required();
  cmd->add_option("b", o->b, "The new run: a run folder or its metrics.json")->required();
  cmd->add_option("--fail-on", o->fail_on,
                  "A regression rule, repeatable: PATH, delta(PATH) or ratio(PATH), then < <= > >=, then a number, "
                  "e.g. 'delta(evaluation.mean.f1) < -0.01' or 'ratio(timing_ms.frame.p50) > 1.2'")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--no-default-rules", o->no_default_rules, "Only the --fail-on rules (and the checks)");
  cmd->add_option("--markdown", o->markdown, "Also write the Markdown (for a pull-request comment) to this file");
  cmd->add_option("--html", o->html, "Also write an HTML page to this file");
  cmd->add_option("--junit", o->junit, "Also write JUnit XML (a testcase per rule and check; skipped: not judged)");
  return [o] { return compare(*o); };
});

}  // namespace
}  // namespace stvl::tools
