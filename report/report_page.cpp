#include "report/report_page.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/markup.hpp"

namespace stvl::report {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Millimetres and microseconds are enough for a picture; the numbers stay short.
double rounded(double v, double step) { return std::isfinite(v) ? std::round(v / step) * step : 0.0; }

nlohmann::json series(const std::vector<double>& values, double step) {
  nlohmann::json out = nlohmann::json::array();
  for (double v : values) out.push_back(rounded(v, step));
  return out;
}

nlohmann::json flat_points(const Eigen::Matrix3Xf& points) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < points.cols(); ++i)
    for (int k = 0; k < 3; ++k) out.push_back(rounded(points(k, i), 0.001));
  return out;
}

nlohmann::json page_data(const PageSeries& p, const std::vector<evaluation::EvaluationSnapshot>& snapshots) {
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, ms] : p.stages) stages[name] = series(*ms, 0.001);
  nlohmann::json quality = {{"t", nlohmann::json::array()},
                            {"f1", nlohmann::json::array()},
                            {"precision", nlohmann::json::array()},
                            {"recall", nlohmann::json::array()}};
  for (const auto& s : snapshots) {
    quality["t"].push_back(rounded(s.time_s, 0.001));
    quality["f1"].push_back(rounded(s.f1, 1e-4));
    quality["precision"].push_back(rounded(s.precision, 1e-4));
    quality["recall"].push_back(rounded(s.recall, 1e-4));
  }
  nlohmann::json drive = nullptr;
  if (p.drive) {
    const evaluation::DriveSummary& d = *p.drive;
    drive = {{"t", nlohmann::json::array()},      {"v", nlohmann::json::array()},
             {"w", nlohmann::json::array()},      {"events", nlohmann::json::array()},
             {"stalls", nlohmann::json::array()}, {"collisions", nlohmann::json::array()}};
    for (const auto& s : d.trajectory) {
      drive["t"].push_back(rounded(s.time_s, 0.001));
      drive["v"].push_back(rounded(s.v_mps, 0.001));
      drive["w"].push_back(rounded(s.omega_radps, 0.001));
    }
    for (const auto& e : d.events)
      if (e.kind != "plan")
        drive["events"].push_back({{"t", rounded(e.time_s, 0.001)}, {"kind", e.kind}, {"detail", e.detail}});
    for (const auto& st : d.stalls) drive["stalls"].push_back({rounded(st.from_s, 0.001), rounded(st.to_s, 0.001)});
    for (const auto& c : d.collisions)
      drive["collisions"].push_back({{"t", rounded(c.time_s, 0.001)}, {"body", c.body}});
  }
  nlohmann::json timing = nullptr;
  if (p.frame_events && !p.frame_events->empty()) {
    timing = {{"cameras", p.camera_names}, {"events", nlohmann::json::array()}};
    for (const auto& e : *p.frame_events)
      timing["events"].push_back({e.camera_index, rounded(e.capture_s, 0.001),
                                  e.delivered_s < 0 ? -1.0 : rounded(e.delivered_s - e.capture_s, 0.0001), e.reason});
    // The localizer's corrections: each one's position error (at most 2000, evenly taken).
    if (p.corrections && !p.corrections->empty()) {
      const std::size_t n = p.corrections->size(), step = (n + 1999) / 2000;
      timing["localization"] = nlohmann::json::array();
      for (std::size_t i = 0; i < n; i += step) {
        const auto& c = (*p.corrections)[i];
        timing["localization"].push_back(
            {rounded(c.time_s, 0.001), rounded(std::hypot(c.error.x_m, c.error.y_m), 0.001)});
      }
    }
  }
  nlohmann::json path = nlohmann::json::array();
  for (const auto& xy : *p.path_W) path.push_back(rounded(xy.x(), 0.001)), path.push_back(rounded(xy.y(), 0.001));
  const MapView& v = *p.view;
  return {{"stages", stages},
          {"quality", quality},
          {"points_raw", nlohmann::json(*p.points_raw)},
          {"points_filtered", nlohmann::json(*p.points_filtered)},
          {"map_voxels", nlohmann::json(*p.map_voxels)},
          {"drive", drive},
          {"timing", timing},
          {"view",
           {{"voxel_m", v.voxel_size_m},
            {"tp", flat_points(v.mapped_true_W)},
            {"fp", flat_points(v.mapped_false_W)},
            {"truth", flat_points(v.truth_W)},
            {"unjudged", flat_points(v.unjudged_W)},
            {"path", path}}}};
}

PageSeries run_series(const RunResult& r) {
  const auto& t = r.times;
  PageSeries p;
  p.stages = {{"render", &t.render}, {"noise", &t.noise}, {"cloud", &t.cloud},           {"filter", &t.filter},
              {"clear", &t.clear},   {"mark", &t.mark},   {"evaluation", &t.evaluation}, {"bag", &t.bag}};
  p.points_raw = &r.points_raw, p.points_filtered = &r.points_filtered, p.map_voxels = &r.map_voxels;
  p.path_W = &r.path_W, p.view = &r.map_view;
  if (r.drive) p.drive = &*r.drive;
  if (!r.frame_events.empty()) {
    p.frame_events = &r.frame_events;
    for (const auto& c : r.scenario.pipeline.cameras) p.camera_names.push_back(c.name);
    p.corrections = &r.corrections;
  }
  return p;
}

const char* const kErrorCapture = R"(<script>
window.__errors = [];
window.addEventListener('error', function (e) { window.__errors.push(String(e.message || e)); });
(function () { var original = console.error; console.error = function () {
  window.__errors.push(Array.prototype.join.call(arguments, ' ')); original.apply(console, arguments); }; })();
</script>
)";

const char* const kPageScript = R"JS(
document.addEventListener('DOMContentLoaded', function () {
  var D = JSON.parse(document.getElementById('report-data').textContent);
  var colors = {render: '#e6780f', noise: '#b4a01e', cloud: '#8c6bb1', filter: '#1e78dc', clear: '#c82828',
                mark: '#28a03c', evaluation: '#777777', bag: '#222222'};
  var frames = D.points_raw.map(function (_, i) { return i; });
  function chart(id, config) {
    config.options = Object.assign({animation: false, responsive: true, maintainAspectRatio: false,
                                    interaction: {mode: 'index', intersect: false}}, config.options || {});
    return new Chart(document.getElementById(id), config);
  }
  function axes(x, y, extra) {
    return {x: Object.assign({title: {display: true, text: x}}, (extra || {}).x || {}),
            y: Object.assign({title: {display: true, text: y}}, (extra || {}).y || {})};
  }
  chart('chart-stages', {type: 'line', data: {labels: frames, datasets: Object.keys(D.stages).map(function (k) {
      return {label: k, data: D.stages[k], borderColor: colors[k], backgroundColor: colors[k], fill: true,
              pointRadius: 0, borderWidth: 1};
    })}, options: {scales: axes('frame', 'wall time per frame (ms), stacked by stage', {y: {stacked: true}})}});
  if (document.getElementById('chart-quality')) chart('chart-quality', {type: 'line', data: {labels: D.quality.t.map(function (t) { return t.toFixed(2); }), datasets: [
      {label: 'F1', data: D.quality.f1, borderColor: '#000', backgroundColor: '#000'},
      {label: 'precision', data: D.quality.precision, borderColor: '#c82828', backgroundColor: '#c82828'},
      {label: 'recall', data: D.quality.recall, borderColor: '#285ae6', backgroundColor: '#285ae6'}]},
    options: {scales: axes('simulated time (s)', 'score (0 to 1)', {y: {min: 0, max: 1}})}});
  chart('chart-points', {type: 'line', data: {labels: frames, datasets: [
      {label: 'raw points', data: D.points_raw, borderColor: '#e6780f', backgroundColor: '#e6780f', pointRadius: 0},
      {label: 'decimated, in the marking band', data: D.points_filtered, borderColor: '#1e78dc',
       backgroundColor: '#1e78dc', pointRadius: 0}]},
    options: {scales: axes('frame', 'points per frame (log scale)', {y: {type: 'logarithmic'}})}});
  chart('chart-voxels', {type: 'line', data: {labels: frames, datasets: [
      {label: 'voxels in the map', data: D.map_voxels, borderColor: '#28a03c', backgroundColor: '#28a03c', pointRadius: 0}]},
    options: {scales: axes('frame', 'voxels')}});
  if (D.timing && document.getElementById('chart-timing')) {
    // Camera timing: each delivered frame's delay from capture to the layer (one colour per camera); frames that
    // never reached it as crosses on the zero line, one colour per reason.
    var T = D.timing, palette = ['#1e78dc', '#28a03c', '#8c6bb1', '#e6780f'];
    var reasons = {camera: '#777777', tf_timeout: '#dc2828', queue_full: '#ff8c00', after_end: '#bbbbbb'};
    var sets = T.cameras.map(function (name, c) {
      return {label: name + ': delay (s)', type: 'scatter', pointRadius: 2, borderColor: palette[c % 4],
              backgroundColor: palette[c % 4], data: T.events.filter(function (e) {
                return e[0] === c && e[3] === 'delivered'; }).map(function (e) {
                return {x: e[1], y: e[2], what: name + ' delivered after ' + e[2].toFixed(3) + ' s'}; })};
    });
    Object.keys(reasons).forEach(function (r) {
      var pts = T.events.filter(function (e) { return e[3] === r; }).map(function (e) {
        return {x: e[1], y: 0, what: T.cameras[e[0]] + ': dropped (' + r + ')'}; });
      if (pts.length) sets.push({label: 'dropped: ' + r + ' (' + pts.length + ')', type: 'scatter', data: pts,
                                 pointStyle: 'crossRot', pointRadius: 5, borderColor: reasons[r],
                                 backgroundColor: reasons[r]});
    });
    var scales = axes('capture time (s)', 'capture to the layer (s)', {x: {type: 'linear', min: 0}, y: {min: 0}});
    if (T.localization) {  // the localizer's error at each correction, on its own axis
      sets.push({label: 'localization error (m)', type: 'line', yAxisID: 'y2', pointRadius: 0, borderWidth: 1.5,
                 borderColor: '#dc2828', backgroundColor: '#dc2828', data: T.localization.map(function (e) {
                   return {x: e[0], y: e[1], what: 'localization off by ' + e[1].toFixed(3) + ' m'}; })});
      scales.y2 = {position: 'right', min: 0, grid: {drawOnChartArea: false},
                   title: {display: true, text: 'localization error (m)'}};
    }
    chart('chart-timing', {type: 'scatter', data: {datasets: sets}, options: {
        interaction: {mode: 'nearest', intersect: true},
        plugins: {tooltip: {callbacks: {label: function (c) { return c.raw.what; }}}},
        scales: scales}});
  }
  if (D.drive && document.getElementById('chart-drive')) {
    // The drive over simulated time: speed and turn rate from the truth; events as markers on a lane each above
    // them (the tooltip names them), stalls as purple bars along the bottom, collisions as dark red crosses.
    var R = D.drive, top = 0.1;
    R.v.concat(R.w).forEach(function (x) { top = Math.max(top, Math.abs(x)); });
    var lanes = {recovery: ['recoveries', '#ff8c00', 1.5], plan_failed: ['failures', '#dc2828', 1.4],
                 controller_failed: ['failures', '#dc2828', 1.4], navigation_failed: ['failures', '#dc2828', 1.4],
                 clear_local_costmap: ['costmap clearings', '#285ae6', 1.3],
                 clear_global_costmap: ['costmap clearings', '#285ae6', 1.3], goal_reached: ['goal', '#1ea03c', 1.2]};
    var marks = {};
    R.events.forEach(function (e) {
      var lane = lanes[e.kind] || ['other events', '#777777', 1.6];
      (marks[lane[0]] = marks[lane[0]] || {color: lane[1], points: []}).points.push(
          {x: e.t, y: lane[2] * top, what: e.kind + (e.detail ? ': ' + e.detail : '')});
    });
    function xy(ys) { return R.t.map(function (t, i) { return {x: t, y: ys[i]}; }); }
    var sets = [
      {label: 'speed (m/s)', data: xy(R.v), borderColor: '#000', backgroundColor: '#000', pointRadius: 0,
       borderWidth: 1.5},
      {label: 'turn rate (rad/s)', data: xy(R.w), borderColor: '#a0a0a0', backgroundColor: '#a0a0a0', pointRadius: 0,
       borderWidth: 1}];
    Object.keys(marks).forEach(function (k) {
      sets.push({label: k, type: 'scatter', data: marks[k].points, borderColor: marks[k].color,
                 backgroundColor: marks[k].color, pointRadius: 5, pointStyle: 'triangle'});
    });
    var stalls = [];
    R.stalls.forEach(function (s) {
      stalls.push({x: s[0], y: -top * 1.05}, {x: s[1], y: -top * 1.05}, {x: s[1], y: null});
    });
    if (stalls.length) sets.push({label: 'stalled', data: stalls, borderColor: '#b48cd2', backgroundColor: '#b48cd2',
                                  borderWidth: 8, pointRadius: 0, spanGaps: false});
    if (R.collisions.length) sets.push({label: 'collisions', type: 'scatter', borderColor: '#6e0000',
        backgroundColor: '#6e0000', pointStyle: 'crossRot', pointRadius: 9, borderWidth: 3,
        data: R.collisions.map(function (c) { return {x: c.t, y: 0, what: 'collision with ' + c.body}; })});
    chart('chart-drive', {type: 'line', data: {datasets: sets}, options: {
        interaction: {mode: 'nearest', intersect: false},
        plugins: {tooltip: {callbacks: {label: function (c) {
          return c.raw && c.raw.what ? c.raw.what : c.dataset.label + ': ' + c.parsed.y.toFixed(3); }}}},
        scales: axes('simulated time (s)', 'speed (m/s), turn rate (rad/s)',
                     {x: {type: 'linear', min: 0}, y: {min: -top * 1.15, max: top * 1.7}})}});
  }

  // 3D view: world frame, z up.
  var canvas = document.getElementById('view3d');
  var renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: false, preserveDrawingBuffer: true});
  renderer.setSize(canvas.clientWidth, canvas.clientHeight, false);
  var scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);
  var box = new THREE.Box3(), mapped = new THREE.Box3();
  function cloud(flat, color, opacity) {
    if (!flat.length) return;
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(flat, 3));
    g.computeBoundingBox();
    box.union(g.boundingBox);
    if (opacity >= 1) mapped.union(g.boundingBox);
    scene.add(new THREE.Points(g, new THREE.PointsMaterial({color: color, size: D.view.voxel_m * 0.9,
      sizeAttenuation: true, transparent: opacity < 1, opacity: opacity, depthWrite: opacity >= 1})));
  }
  cloud(D.view.truth, 0x999999, 0.25);
  cloud(D.view.tp, 0x1e9e3c, 1);
  cloud(D.view.fp, 0xdc2828, 1);
  cloud(D.view.unjudged, 0x1e78dc, 1);
  if (D.view.path.length >= 4) {
    var path = [];
    for (var i = 0; i < D.view.path.length; i += 2) path.push(D.view.path[i], D.view.path[i + 1], 0.01);
    var pg = new THREE.BufferGeometry();
    pg.setAttribute('position', new THREE.Float32BufferAttribute(path, 3));
    scene.add(new THREE.Line(pg, new THREE.LineBasicMaterial({color: 0x000000})));
  }
  // Look at the map (the truth around it stays in view when zooming out).
  if (!mapped.isEmpty()) box = mapped;
  if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, 0), new THREE.Vector3(1, 1, 1));
  var center = box.getCenter(new THREE.Vector3());
  var size = box.getSize(new THREE.Vector3());
  var extent = Math.max(size.x, size.y, 2);
  var camera = new THREE.PerspectiveCamera(50, canvas.clientWidth / canvas.clientHeight, 0.05, 10 * extent);
  camera.up.set(0, 0, 1);
  camera.position.set(center.x - 0.45 * extent, center.y - 0.75 * extent, center.z + 0.5 * extent);
  var controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(center);
  controls.update();
  function render() { renderer.render(scene, camera); }
  controls.addEventListener('change', render);
  render();

  // Top-down zoom.
  var zoom = document.getElementById('topdown-zoom');
  if (zoom) zoom.addEventListener('input', function () {  // 1: fit the page; above: the picture's own size times the zoom
    var img = document.getElementById('topdown');
    img.style.maxWidth = zoom.value > 1 ? 'none' : '100%';
    img.style.width = zoom.value > 1 ? (img.naturalWidth * zoom.value) + 'px' : '';
  });

  // Self-check for the browser test: painted pixels of every chart and of the 3D view.
  function painted2d(c) {
    var d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data, n = 0;
    for (var i = 3; i < d.length; i += 4) if (d[i] > 0) n++;
    return n;
  }
  function painted3d() {
    var gl = renderer.getContext(), w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    var px = new Uint8Array(w * h * 4), n = 0;
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    for (var i = 0; i < px.length; i += 4) if (px[i] < 245 || px[i + 1] < 245 || px[i + 2] < 245) n++;
    return n;
  }
  var charts = {};
  document.querySelectorAll('canvas.chart').forEach(function (c) { charts[c.id] = painted2d(c); });
  document.getElementById('selftest').textContent = JSON.stringify(
    {errors: window.__errors, charts: charts, view3d: painted3d(), view3d_points: {
      tp: D.view.tp.length / 3, fp: D.view.fp.length / 3, truth: D.view.truth.length / 3,
      unjudged: D.view.unjudged.length / 3}});
});
)JS";

}  // namespace

ReportScripts load_report_scripts(const std::string& root) {
  ReportScripts s;
  s.chart_js = read_text(root + "/chart.js/chart.min.js");
  s.three_js = read_text(root + "/three/three.min.js");
  s.orbit_controls_js = read_text(root + "/three/examples/js/controls/OrbitControls.js");
  return s;
}

std::string interactive_head_html(const ReportScripts& scripts) {
  if (!scripts.complete()) return "";
  std::ostringstream h;
  h << kErrorCapture << "<script>" << script_safe(scripts.chart_js) << "</script>\n<script>"
    << script_safe(scripts.three_js) << "</script>\n<script>" << script_safe(scripts.orbit_controls_js) << "</script>\n"
    << "<style>.chartbox{position:relative;height:300px;max-width:1200px;margin-bottom:1em}"
       "#view3d{width:100%;max-width:1400px;height:640px;border:1px solid #ddd;display:block}</style>\n";
  return h.str();
}

namespace {

const char* const kMissingScripts =
    "<p><b>No interactive charts or 3D view:</b> the page inlines Debian's libjs-chart.js and libjs-three, "
    "which were not installed when this run wrote it (scripts/install-deps.sh installs them).</p>\n";

std::string body_html(const nlohmann::json& data, const std::vector<const char*>& charts, const std::string& caption) {
  std::ostringstream h;
  h << "<h2>Charts</h2>\n";
  for (const char* id : charts)
    h << "<div class=\"chartbox\"><canvas class=\"chart\" id=\"" << id << "\"></canvas></div>\n";
  h << "<h2>The final map in 3D</h2><p>" << caption << " Drag to orbit, wheel to zoom, right-drag to pan.</p>\n"
    << "<canvas id=\"view3d\"></canvas>\n"
    << "<script type=\"application/json\" id=\"report-data\">" << script_safe(data.dump()) << "</script>\n"
    << "<pre id=\"selftest\" style=\"display:none\"></pre>\n<script>" << kPageScript << "</script>\n";
  return h.str();
}

}  // namespace

std::string interactive_body_html(const RunResult& r, const ReportScripts& scripts) {
  if (!scripts.complete()) return kMissingScripts;
  const MapView& v = r.map_view;
  std::ostringstream caption;
  caption << "Voxels within " << r.scenario.evaluation.tolerance_voxels << " voxel of a true surface in green ("
          << v.mapped_true << "), the others in red (" << v.mapped_false << "), the truth's voxels faint grey ("
          << v.truth << "), the robot's path in black.";
  if (v.mapped_true_W.cols() < Eigen::Index(v.mapped_true) || v.mapped_false_W.cols() < Eigen::Index(v.mapped_false) ||
      v.truth_W.cols() < Eigen::Index(v.truth))
    caption << " Thinned for the browser to about " << v.truth_W.cols()
            << " voxels per colour, chosen by a hash of the voxel key.";
  std::vector<const char*> charts{"chart-stages", "chart-quality", "chart-points", "chart-voxels"};
  if (!r.frame_events.empty()) charts.push_back("chart-timing");  // camera timing: delays and drops
  return body_html(page_data(run_series(r), r.evaluation.snapshots), charts, caption.str());
}

std::string interactive_body_html(const PageSeries& series, const std::string& view_caption_html,
                                  const ReportScripts& scripts) {
  if (!scripts.complete()) return kMissingScripts;
  return body_html(page_data(series, {}), {"chart-stages", "chart-points", "chart-voxels"}, view_caption_html);
}

}  // namespace stvl::report
