#pragma once
// A sweep (stvl-bench sweep): the Cartesian grid of scenario assignments ("--set KEY=V1,V2,..." and seeds), each
// point one independent `stvl-bench run` with its own output folder. The grid runs here (--jobs N) or is written
// out for an existing engine: a GNU parallel job file, a CTest file (one test per point), a Slurm job array.
// `--collect DIR` merges every point's metrics.json into one table (CSV, JSON, HTML with charts).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace stvl::analysis {

struct SweepAxis {
  std::string key;                  // a dotted scenario key, as run --set takes it; or a run option ("--voxel-size")
  std::vector<std::string> values;  // YAML texts (option values as run takes them)
  bool run_option() const { return key.rfind("--", 0) == 0; }
};

// The run options an axis may vary (--option NAME=V1,V2): they set more than one key (--voxel-size sets the
// map's and the filter's voxel size together) or are not scenario keys.
const std::vector<std::string>& sweep_run_options();  // voxel-size, filter, device, memory, duration, noise, gl

struct SweepPoint {
  std::size_t index = 0;
  std::string name;  // its folder: "003_map.voxel_size=0.05_seed=2" (safe characters; axes of one value left out)
  std::vector<std::string> sets;             // "KEY=VALUE" per axis, in axis order ("--voxel-size=0.05" for options)
  std::optional<std::uint64_t> seed;         // absent without --seeds
};

// "KEY=V1,V2,..." to an axis; commas inside [] or {} do not split ("robot.start=[0, 0, 0],[1, 0, 0]").
// option: the axis is a run option (NAME one of sweep_run_options()). Throws std::invalid_argument naming the
// argument for a missing '=', an empty key or value, or an unknown option.
SweepAxis parse_sweep_axis(const std::string& text, bool option = false);
// "1..5", "3", "1,4,9" (or mixed: "1..3,7") to seeds; throws std::invalid_argument for anything else or none.
std::vector<std::uint64_t> parse_seeds(const std::string& text);

// Every combination, the first axis varying slowest, seeds fastest. Throws std::invalid_argument for an empty
// grid or more than max_points points.
std::vector<SweepPoint> sweep_grid(const std::vector<SweepAxis>& axes, const std::vector<std::uint64_t>& seeds,
                                   std::size_t max_points = 10000);

// The argument vector of a point's run: BIN run SCENARIO --out OUT_DIR/NAME --no-progress [--set ...] [--seed S].
std::vector<std::string> point_command(const std::string& binary, const std::string& scenario, const std::string& out_dir,
                                       const SweepPoint& point);
// One shell command line (arguments single-quoted).
std::string shell_line(const std::vector<std::string>& argv);

// The engines' files, written into out_dir (atomically): sweep.json (the grid: each point's name and sets, for
// --collect) always, and
//   parallel: jobs.txt, one command per line (`parallel --jobs N < jobs.txt`);
//   ctest:    CTestTestfile.cmake, one test per point named sweep.NAME (`ctest --test-dir DIR -j N`);
//   slurm:    jobs.txt and sweep.sbatch, an array job whose task i runs line i + 1 (`sbatch sweep.sbatch`).
// Returns the paths written. Throws std::invalid_argument for an unknown engine.
std::vector<std::string> emit_sweep(const std::string& engine, const std::string& binary, const std::string& scenario,
                                    const std::string& out_dir, const std::vector<SweepPoint>& points);

// Runs the points here, at most `jobs` at a time, each a child process (its output in OUT_DIR/NAME.log). Returns
// the worst exit code (0 all passed, 1 a check failed, 2 bad input or a crash).
int run_sweep_locally(const std::string& binary, const std::string& scenario, const std::string& out_dir,
                      const std::vector<SweepPoint>& points, int jobs);

// Merges DIR/sweep.json's points with their DIR/NAME/metrics.json: one row per point (its sets, seed, exit state
// and headline figures). Writes DIR/sweep.csv, DIR/sweep_table.json and DIR/sweep.html (Chart.js inlined from
// chart_js_path when that file exists: F1 and filter ms per point, grouped by the other axes). Returns the
// table. Throws std::invalid_argument when DIR has no sweep.json; points without metrics.json are rows with
// "missing" and no figures.
nlohmann::json collect_sweep(const std::string& dir, const std::string& chart_js_path = "/usr/share/javascript/chart.js/chart.min.js");

}  // namespace stvl::analysis
