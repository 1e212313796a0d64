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

// One world of a --worlds axis: its label ("generate:17", or a map's or a scenario's file name), the scenario its
// points run, and the shell command that made that scenario (empty for a scenario file given as it is).
struct SweepWorld {
  std::string label, scenario, make_command;
};

// "generate:SEEDS" (SEEDS as parse_seeds takes them) or a comma-separated list of files: nav2 maps (a map_server
// YAML, told by its `image` key) and scenario files. Generated worlds and maps become worlds now, in
// OUT_DIR/worlds/<label>, by `BINARY world generate --seed N` and `BINARY world from-map FILE`. Throws
// std::invalid_argument naming the entry for a bad spec, a missing file, or a world command that fails (with its
// output).
std::vector<SweepWorld> prepare_worlds(const std::string& binary, const std::string& spec, const std::string& out_dir);

struct SweepPoint {
  std::size_t index = 0;
  std::string world;       // its world's label (a --worlds axis), or empty
  std::string scenario;    // the scenario it runs when not the sweep's own (a --worlds axis)
  std::string make_world;  // the command that made that scenario, or empty
  std::string name;        // its folder: "003_map.voxel_size=0.05_seed=2" (safe characters; axes of one value left out)
  std::vector<std::string> sets;      // "KEY=VALUE" per axis, in axis order ("--voxel-size=0.05" for options)
  std::optional<std::uint64_t> seed;  // absent without --seeds
};

// "KEY=V1,V2,..." to an axis; commas inside [] or {} do not split ("robot.start=[0, 0, 0],[1, 0, 0]").
// option: the axis is a run option (NAME one of sweep_run_options()). Throws std::invalid_argument naming the
// argument for a missing '=', an empty key or value, or an unknown option.
SweepAxis parse_sweep_axis(const std::string& text, bool option = false);
// "1..5", "3", "1,4,9" (or mixed: "1..3,7") to seeds; throws std::invalid_argument for anything else or none.
std::vector<std::uint64_t> parse_seeds(const std::string& text);

// Every combination, the worlds varying slowest, then the axes in order, seeds fastest. Throws
// std::invalid_argument for an empty grid or more than max_points points.
std::vector<SweepPoint> sweep_grid(const std::vector<SweepAxis>& axes, const std::vector<std::uint64_t>& seeds,
                                   std::size_t max_points = 10000, const std::vector<SweepWorld>& worlds = {});

// A twin of every point (sweep --twin OUT;KEY=VALUE;...): the same point with more --sets, run on the point's drive
// (run --twin) into its own sweep folder, out_dir, which --collect reads like any sweep.
struct SweepTwin {
  std::string out_dir;
  std::vector<std::string> sets;
};

// The argument vector of a point's run: BIN run SCENARIO --out OUT_DIR/NAME --no-progress [--set ...] [--seed S]
// (the point's own scenario when it has one), and --twin TWIN_DIR/NAME;SET;... per twin.
std::vector<std::string> point_command(const std::string& binary, const std::string& scenario,
                                       const std::string& out_dir, const SweepPoint& point,
                                       const std::vector<SweepTwin>& twins = {});
// One shell command line (arguments single-quoted).
std::string shell_line(const std::vector<std::string>& argv);

// The engines' files, written into out_dir (atomically): sweep.json (the grid: each point's name and sets, for
// --collect) always, and
//   parallel: jobs.txt, one command per line (`parallel --jobs N < jobs.txt`);
//   ctest:    CTestTestfile.cmake, one test per point named sweep.NAME (`ctest --test-dir DIR -j N`);
//   slurm:    jobs.txt and sweep.sbatch, an array job whose task i runs line i + 1 (`sbatch sweep.sbatch`).
// Each twin's folder gets a sweep.json of its own (its points' sets: the point's, then the twin's). Returns the paths
// written. Throws std::invalid_argument for an unknown engine.
std::vector<std::string> emit_sweep(const std::string& engine, const std::string& binary, const std::string& scenario,
                                    const std::string& out_dir, const std::vector<SweepPoint>& points,
                                    const std::vector<SweepTwin>& twins = {});

// Runs the points here, at most `jobs` at a time, each a child process (its output in OUT_DIR/NAME.log). Returns
// the worst exit code (0 all passed, 1 a check failed, 2 bad input or a crash).
int run_sweep_locally(const std::string& binary, const std::string& scenario, const std::string& out_dir,
                      const std::vector<SweepPoint>& points, int jobs, const std::vector<SweepTwin>& twins = {});

// Merges DIR/sweep.json's points with their DIR/NAME/metrics.json: one row per point (its sets, seed, exit state
// and headline figures). Writes DIR/sweep.csv, DIR/sweep_table.json and DIR/sweep.html (Chart.js inlined from
// chart_js_path when that file exists: F1 and filter ms per point, grouped by the other axes). Returns the
// table. Throws std::invalid_argument when DIR has no sweep.json; points without metrics.json are rows with
// "missing" and no figures.
nlohmann::json collect_sweep(const std::string& dir,
                             const std::string& chart_js_path = "/usr/share/javascript/chart.js/chart.min.js");

}  // namespace stvl::analysis
