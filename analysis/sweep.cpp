#include "analysis/sweep.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>

#include "analysis/sweep_page.hpp"
#include "analysis/sweep_worlds.hpp"
#include "common/atomic_file.hpp"
#include "common/enum_names.hpp"
#include "common/markup.hpp"

extern char** environ;

namespace stvl::analysis {
namespace fs = std::filesystem;
namespace {

std::string trim(const std::string& text) {
  const std::size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t") - begin + 1);
}

// A folder-name-safe form of "KEY=VALUE": letters, digits and ._=- kept, the rest '-'.
std::string safe(const std::string& text) {
  std::string out;
  for (char c : text)
    out += std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '=' || c == '-' ? c : '-';
  return out;
}

// Headline figures of a run, by their path in metrics.json (column names in the table).
const std::vector<std::pair<std::string, std::vector<std::string>>>& headline() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> figures = {
      {"f1", {"evaluation", "mean", "f1"}},
      {"precision", {"evaluation", "mean", "precision"}},
      {"recall", {"evaluation", "mean", "recall"}},
      {"costmap_precision", {"evaluation", "mean", "costmap_precision"}},
      {"final_phantoms", {"evaluation", "final", "phantom_obstacles"}},
      {"filtered_points_mean", {"points", "filtered_mean"}},
      {"filter_ms_mean", {"timing_ms", "filter", "mean"}},
      {"clear_ms_mean", {"timing_ms", "clear", "mean"}},
      {"mark_ms_mean", {"timing_ms", "mark", "mean"}},
      {"frame_ms_mean", {"timing_ms", "frame", "mean"}},
      {"real_time_factor", {"real_time_factor"}}};
  return figures;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

const std::vector<std::string>& sweep_run_options() {
  static const std::vector<std::string> options = {"voxel-size", "filter", "device", "memory",
                                                   "duration",   "noise",  "gl"};
  return options;
}

SweepAxis parse_sweep_axis(const std::string& text, bool option) {
  const std::string flag = option ? "--option " : "--set ";
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos) throw std::invalid_argument(flag + text + ": expected KEY=V1,V2,...");
  SweepAxis axis;
  axis.key = trim(text.substr(0, equals));
  if (axis.key.empty()) throw std::invalid_argument(flag + text + ": empty key");
  if (option) {
    const auto& known = sweep_run_options();
    if (std::find(known.begin(), known.end(), axis.key) == known.end()) {
      const std::string hint = nearest_name(axis.key, known);
      throw std::invalid_argument(flag + text + ": unknown run option '" + axis.key + "'" +
                                  (hint.empty() ? "" : "; did you mean '" + hint + "'?"));
    }
    axis.key = "--" + axis.key;
  }
  int depth = 0;
  std::string value;
  const std::string list = text.substr(equals + 1);
  for (std::size_t i = 0; i <= list.size(); ++i) {
    const char c = i < list.size() ? list[i] : ',';
    if (c == '[' || c == '{') ++depth;
    if (c == ']' || c == '}') --depth;
    if (c == ',' && depth <= 0) {
      if (trim(value).empty()) throw std::invalid_argument(flag + text + ": empty value in the list");
      axis.values.push_back(trim(value));
      value.clear();
    } else {
      value += c;
    }
  }
  return axis;
}

std::vector<std::uint64_t> parse_seeds(const std::string& text) {
  std::vector<std::uint64_t> seeds;
  const auto number = [&](const std::string& digits) -> std::uint64_t {
    if (digits.empty() || digits.size() > 19 || digits.find_first_not_of("0123456789") != std::string::npos)
      throw std::invalid_argument("--seeds " + text + ": expected seeds like 1..5, 3 or 1,4,9");
    return std::stoull(digits);
  };
  std::stringstream parts(text);
  std::string part;
  while (std::getline(parts, part, ',')) {
    part = trim(part);
    const std::size_t dots = part.find("..");
    if (dots == std::string::npos) {
      seeds.push_back(number(part));
      continue;
    }
    const std::uint64_t first = number(part.substr(0, dots)), last = number(part.substr(dots + 2));
    if (last < first || last - first >= 10000)
      throw std::invalid_argument("--seeds " + text + ": a range must run upwards, at most 10000 seeds");
    for (std::uint64_t s = first; s <= last; ++s) seeds.push_back(s);
  }
  if (seeds.empty()) throw std::invalid_argument("--seeds " + text + ": no seed");
  return seeds;
}

std::vector<SweepWorld> prepare_worlds(const std::string& binary, const std::string& spec, const std::string& out_dir) {
  const fs::path root = fs::absolute(out_dir) / "worlds";
  std::vector<std::pair<std::string, std::vector<std::string>>> makes;  // label, world command
  std::vector<SweepWorld> worlds;
  if (spec.rfind("generate:", 0) == 0) {
    for (const std::uint64_t seed : parse_seeds(spec.substr(9))) {
      const std::string label = "generate:" + std::to_string(seed);
      makes.push_back({label,
                       {binary, "world", "generate", "--seed", std::to_string(seed), "--out",
                        (root / ("generate_" + std::to_string(seed))).string()}});
    }
  } else {
    std::stringstream list(spec);
    std::string entry;
    while (std::getline(list, entry, ',')) {
      entry = trim(entry);
      if (entry.empty()) continue;
      std::error_code error;
      if (!fs::is_regular_file(entry, error))
        throw std::invalid_argument("--worlds " + entry + ": no such file (a nav2 map YAML or a scenario)");
      const std::string file = fs::absolute(entry).lexically_normal().string();
      std::ifstream in(file);
      std::string line;
      bool map = false;  // map_server's YAML has a top-level `image:` key; a scenario has none
      while (std::getline(in, line)) map = map || line.rfind("image:", 0) == 0;
      if (!map) {
        worlds.push_back({fs::path(file).filename().string(), file, ""});
        continue;
      }
      const std::string label = "map:" + fs::path(file).stem().string();
      makes.push_back({label,
                       {binary, "world", "from-map", file, "--out",
                        (root / ("map_" + safe(fs::path(file).stem().string()))).string()}});
    }
  }
  for (const auto& [label, argv] : makes) {
    const std::string dir = argv.back();
    std::error_code error;
    fs::remove_all(dir, error);
    fs::create_directories(root);
    const std::string log = dir + ".log";
    const int status = std::system((shell_line(argv) + " > " + shell_line({log}) + " 2>&1").c_str());
    if (status != 0) {
      std::ifstream in(log);
      const std::string output((std::istreambuf_iterator<char>(in)), {});
      throw std::invalid_argument("--worlds " + label + ": `" + shell_line(argv) + "` failed: " + trim(output));
    }
    worlds.push_back({label, (fs::path(dir) / "scenario.yaml").string(), shell_line(argv)});
  }
  if (worlds.empty()) throw std::invalid_argument("--worlds " + spec + ": no world");
  return worlds;
}

std::vector<SweepPoint> sweep_grid(const std::vector<SweepAxis>& axes, const std::vector<std::uint64_t>& seeds,
                                   std::size_t max_points, const std::vector<SweepWorld>& worlds) {
  std::size_t count = (seeds.empty() ? 1 : seeds.size()) * std::max<std::size_t>(1, worlds.size());
  if (count > max_points) throw std::invalid_argument("sweep: more than " + std::to_string(max_points) + " points");
  for (const auto& axis : axes) {
    if (axis.values.empty())
      throw std::invalid_argument("sweep: the axis " + axis.key + " has no value: the grid is empty");
    if (count > max_points / axis.values.size())
      throw std::invalid_argument("sweep: more than " + std::to_string(max_points) + " points");
    count *= axis.values.size();
  }
  if (axes.empty() && seeds.empty() && worlds.empty())
    throw std::invalid_argument("sweep: an empty grid (give --set, --option, --seeds or --worlds)");
  std::vector<SweepPoint> points;
  for (std::size_t i = 0; i < count; ++i) {
    SweepPoint p;
    p.index = i;
    std::size_t rest = i;
    if (!seeds.empty()) p.seed = seeds[rest % seeds.size()], rest /= seeds.size();
    std::vector<std::string> sets(axes.size());
    for (std::size_t a = axes.size(); a-- > 0;) {
      sets[a] = axes[a].key + "=" + axes[a].values[rest % axes[a].values.size()];
      rest /= axes[a].values.size();
    }
    p.sets = sets;
    char prefix[24];
    std::snprintf(prefix, sizeof prefix, "%03zu", i);
    p.name = prefix;
    if (!worlds.empty()) {
      const SweepWorld& w = worlds[rest % worlds.size()];
      p.world = w.label, p.scenario = w.scenario, p.make_world = w.make_command;
      p.name += "_" + safe(w.label);
    }
    for (std::size_t a = 0; a < sets.size(); ++a)  // an axis of one value tells the points apart from nothing
      if (axes[a].values.size() > 1) p.name += "_" + safe(sets[a].rfind("--", 0) == 0 ? sets[a].substr(2) : sets[a]);
    if (p.seed) p.name += "_seed=" + std::to_string(*p.seed);
    points.push_back(std::move(p));
  }
  return points;
}

std::vector<std::string> point_command(const std::string& binary, const std::string& scenario,
                                       const std::string& out_dir, const SweepPoint& point,
                                       const std::vector<SweepTwin>& twins) {
  std::vector<std::string> argv = {binary,
                                   "run",
                                   point.scenario.empty() ? scenario : point.scenario,
                                   "--out",
                                   (fs::path(out_dir) / point.name).string(),
                                   "--no-progress"};
  for (const auto& s : point.sets) {
    const std::size_t equals = s.find('=');
    if (s.rfind("--", 0) == 0) {
      argv.push_back(s.substr(0, equals));
      argv.push_back(s.substr(equals + 1));
    } else {
      argv.push_back("--set");
      argv.push_back(s);
    }
  }
  if (point.seed) argv.insert(argv.end(), {"--seed", std::to_string(*point.seed)});
  for (const SweepTwin& twin : twins) {
    std::string spec = (fs::absolute(twin.out_dir) / point.name).string();
    for (const auto& set : twin.sets) spec += ";" + set;
    argv.insert(argv.end(), {"--twin", spec});
  }
  return argv;
}

std::string shell_line(const std::vector<std::string>& argv) {
  std::string line;
  for (const auto& arg : argv) {
    std::string quoted = "'";
    for (char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += (line.empty() ? "" : " ") + quoted + "'";
  }
  return line;
}

std::vector<std::string> emit_sweep(const std::string& engine, const std::string& binary, const std::string& scenario,
                                    const std::string& out_dir, const std::vector<SweepPoint>& points,
                                    const std::vector<SweepTwin>& twins) {
  if (engine != "parallel" && engine != "ctest" && engine != "slurm")
    throw std::invalid_argument("--emit " + engine + ": expected parallel, ctest or slurm");
  fs::create_directories(out_dir);
  const fs::path dir = fs::absolute(out_dir);
  for (const SweepTwin& twin : twins) fs::create_directories(twin.out_dir);
  std::vector<std::string> written;
  const auto write_in = [&](const fs::path& folder, const std::string& name, const std::string& text) {
    write_file_atomically(folder / name, text);
    written.push_back((folder / name).string());
  };
  const auto write = [&](const std::string& name, const std::string& text) { write_in(dir, name, text); };
  const auto command = [&](const SweepPoint& p) { return point_command(binary, scenario, dir.string(), p, twins); };
  // One grid per folder: a twin's points carry the twin's sets after their own, and the command that makes them.
  for (std::size_t t = 0; t <= twins.size(); ++t) {
    nlohmann::json grid = {{"scenario", scenario}, {"points", nlohmann::json::array()}};
    for (const auto& p : points) {
      std::vector<std::string> sets = p.sets;
      if (t > 0) sets.insert(sets.end(), twins[t - 1].sets.begin(), twins[t - 1].sets.end());
      nlohmann::json point = {{"name", p.name}, {"sets", sets}, {"command", shell_line(command(p))}};
      if (p.seed) point["seed"] = *p.seed;
      if (!p.world.empty()) point["world"] = p.world, point["make_world"] = p.make_world;
      grid["points"].push_back(point);
    }
    write_in(t == 0 ? dir : fs::absolute(twins[t - 1].out_dir), "sweep.json", grid.dump(2) + "\n");
  }
  std::string jobs;
  for (const auto& p : points) jobs += shell_line(command(p)) + "\n";
  if (engine == "parallel" || engine == "slurm") write("jobs.txt", jobs);
  if (engine == "ctest") {
    std::string tests = "# stvl-bench sweep: one test per point; run with ctest --test-dir " + dir.string() + " -j N\n";
    for (const auto& p : points) {
      std::string args;
      for (const auto& arg : command(p)) {
        std::string escaped;
        for (char c : arg)
          escaped += c == '"' || c == '\\' || c == '$' || c == ';' ? std::string("\\") + c : std::string(1, c);
        args += " \"" + escaped + "\"";
      }
      tests +=
          "add_test(sweep." + p.name + args + ")\nset_tests_properties(sweep." + p.name + " PROPERTIES LABELS sweep)\n";
    }
    write("CTestTestfile.cmake", tests);
  }
  if (engine == "slurm") {
    std::ostringstream script;
    script << "#!/bin/bash\n"
           << "# stvl-bench sweep as a Slurm job array: task i runs line i + 1 of jobs.txt. Submit: sbatch "
           << (dir / "sweep.sbatch").string() << "\n"
           << "#SBATCH --job-name=stvl-sweep\n"
           << "#SBATCH --array=0-" << (points.empty() ? 0 : points.size() - 1) << "\n"
           << "#SBATCH --cpus-per-task=2\n"
           << "#SBATCH --output=" << (dir / "slurm-%A_%a.out").string() << "\n"
           << "set -euo pipefail\n"
           << "line=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" " << shell_line({(dir / "jobs.txt").string()}) << ")\n"
           << "eval \"$line\"\n";
    write("sweep.sbatch", script.str());
  }
  return written;
}

int run_sweep_locally(const std::string& binary, const std::string& scenario, const std::string& out_dir,
                      const std::vector<SweepPoint>& points, int jobs, const std::vector<SweepTwin>& twins) {
  if (jobs < 1) throw std::invalid_argument("--jobs must be at least 1");
  // sweep.json (and jobs.txt) for --collect and reruns, in every twin's folder too
  emit_sweep("parallel", binary, scenario, out_dir, points, twins);
  const fs::path dir = fs::absolute(out_dir);
  int worst = 0;
  std::size_t next = 0, running = 0;
  std::map<pid_t, std::string> names;
  const auto reap = [&] {
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid <= 0) return;
    --running;
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 2;
    std::printf("sweep: %s %s\n", names[pid].c_str(),
                code == 0   ? "passed"
                : code == 1 ? "FAILED a check"
                            : "ERROR (see its .log)");
    std::fflush(stdout);
    worst = std::max(worst, std::min(code, 2));
  };
  while (next < points.size() || running > 0) {
    if (next < points.size() && running < static_cast<std::size_t>(jobs)) {
      const SweepPoint& p = points[next++];
      const std::vector<std::string> args = point_command(binary, scenario, dir.string(), p, twins);
      std::vector<char*> argv;
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      const std::string log = (dir / (p.name + ".log")).string();
      posix_spawn_file_actions_t actions;
      posix_spawn_file_actions_init(&actions);
      posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
      pid_t pid = 0;
      const int error = posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ);
      posix_spawn_file_actions_destroy(&actions);
      if (error != 0) throw std::runtime_error("sweep: cannot start " + binary + ": " + std::strerror(error));
      names[pid] = p.name;
      ++running;
    } else {
      reap();
    }
  }
  return worst;
}

namespace {

nlohmann::json read_sweep_grid(const fs::path& grid_path, const std::string& dir_text) {
  std::error_code error;
  if (!fs::is_regular_file(grid_path, error))
    throw std::invalid_argument(dir_text + ": no sweep.json (not a sweep folder)");
  try {
    std::ifstream in(grid_path);
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(grid_path.string() + ": malformed: " + e.what());
  }
}

// The axis a "--key=value" (or "key=value") assignment sets.
std::string sweep_key_of(const std::string& set) {
  const std::string key = set.substr(0, set.find('='));
  return key.rfind("--", 0) == 0 ? key.substr(2) : key;
}

// A point's metrics.json; null when it is missing or malformed.
nlohmann::json read_point_metrics(const fs::path& file) {
  nlohmann::json metrics;
  try {
    std::ifstream in(file);
    if (in) metrics = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    metrics = nlohmann::json();
  }
  return metrics;
}

// One row of sweep_table.json: the point's name, assignments, seed, world, state, checks and headline figures.
nlohmann::json sweep_row(const nlohmann::json& point, const fs::path& dir) {
  const std::string name = point["name"].get<std::string>();
  nlohmann::json row = {{"point", name}, {"sets", nlohmann::json::object()}};
  for (const auto& set : point["sets"]) {
    const std::string s = set.get<std::string>();
    row["sets"][sweep_key_of(s)] = s.substr(s.find('=') + 1);
  }
  if (point.contains("seed")) row["seed"] = std::to_string(point["seed"].get<std::uint64_t>());
  for (const char* key : {"world", "make_world", "command"})
    if (point.contains(key)) row[key] = point[key];
  nlohmann::json metrics = read_point_metrics(dir / name / "metrics.json");
  row["state"] = metrics.is_object() ? (metrics.value("passed", false) ? "passed" : "failed") : "missing";
  row["failed_checks"] = nlohmann::json::array();  // by name, with their messages (sweep.html, --junit)
  row["checks"] = nlohmann::json::object();        // every check's status: pass, fail or skip
  if (metrics.is_object() && metrics.contains("checks"))
    for (const auto& c : metrics["checks"]) {
      const std::string status = c.value("status", c.value("passed", false) ? "pass" : "fail");
      row["checks"][c.value("name", "")] = status;
      if (status == "fail")
        row["failed_checks"].push_back({{"name", c.value("name", "")}, {"message", c.value("message", "")}});
    }
  if (metrics.is_object()) {
    row["figures"] = nlohmann::json::object();
    for (const auto& [figure, path] : headline()) {
      const nlohmann::json* node = &metrics;
      for (const auto& key : path) node = node && node->is_object() && node->contains(key) ? &(*node)[key] : nullptr;
      if (node && node->is_number()) row["figures"][figure] = *node;
    }
  }
  return row;
}

// sweep.csv's header: point[,world], the axes, seed, state, the headline figures.
std::string sweep_csv_header(const nlohmann::json& axes, bool worlds) {
  std::string csv = worlds ? "point,world" : "point";
  for (const auto& axis : axes) csv += "," + csv_field(axis.get<std::string>());
  csv += ",seed,state";
  for (const auto& [name, path] : headline()) csv += "," + name;
  return csv + "\n";
}

std::string sweep_csv_line(nlohmann::json& row, const nlohmann::json& axes, bool worlds) {
  std::string csv = csv_field(row["point"].get<std::string>());
  if (worlds) csv += "," + csv_field(row.value("world", std::string()));
  for (const auto& axis : axes) csv += "," + csv_field(row["sets"].value(axis.get<std::string>(), ""));
  csv += "," + row.value("seed", std::string()) + "," + row["state"].get<std::string>();
  for (const auto& [figure, path] : headline())
    csv += "," +
           (row.contains("figures") && row["figures"].contains(figure) ? row["figures"][figure].dump() : std::string());
  return csv + "\n";
}

}  // namespace

nlohmann::json collect_sweep(const std::string& dir_text, const std::string& chart_js_path) {
  const fs::path dir = dir_text;
  nlohmann::json grid = read_sweep_grid(dir / "sweep.json", dir_text);
  nlohmann::json table = {
      {"scenario", grid.value("scenario", "")}, {"axes", nlohmann::json::array()}, {"rows", nlohmann::json::array()}};
  if (!grid["points"].empty())
    for (const auto& set : grid["points"][0]["sets"]) table["axes"].push_back(sweep_key_of(set.get<std::string>()));
  const bool worlds = !grid["points"].empty() && grid["points"][0].contains("world");
  std::string csv = sweep_csv_header(table["axes"], worlds);
  for (const auto& point : grid["points"]) {
    nlohmann::json row = sweep_row(point, dir);
    csv += sweep_csv_line(row, table["axes"], worlds);
    table["rows"].push_back(row);
  }
  if (worlds) table["over_worlds"] = over_worlds(table);
  write_file_atomically(dir / "sweep.csv", csv);
  write_file_atomically(dir / "sweep_table.json", table.dump(2) + "\n");

  std::vector<std::string> columns;
  for (const auto& [figure, path] : headline()) columns.push_back(figure);
  const std::string html = sweep_html(table, columns, chart_js_path);
  write_file_atomically(dir / "sweep.html", html);
  return table;
}

}  // namespace stvl::analysis
