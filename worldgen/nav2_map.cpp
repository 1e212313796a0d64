#include "worldgen/nav2_map.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/enum_names.hpp"
#include "common/png.hpp"

namespace stvl::worldgen {
namespace {

constexpr const char* kKnownKeys[] = {"image",           "resolution",  "origin", "negate",
                                      "occupied_thresh", "free_thresh", "mode"};

// "FILE:LINE: KEY: message" (the line of `node`, or of the document when it has none).
[[noreturn]] void fail(const std::string& file, const YAML::Node& node, const std::string& key,
                       const std::string& message) {
  std::ostringstream text;
  const YAML::Mark mark = node.IsDefined() ? node.Mark() : YAML::Mark::null_mark();
  text << file << ":" << (mark.is_null() || mark.line < 0 ? 1 : mark.line + 1) << ": "
       << (key.empty() ? "" : key + ": ") << message;
  throw std::invalid_argument(text.str());
}

double number(const std::string& file, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) fail(file, node, key, "expected a number; write e.g. " + key + ": 0.05");
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    fail(file, node, key, "expected a number, got '" + node.Scalar() + "'");
  }
}

// Skips whitespace and '#' comments up to the end of their line.
void skip_space(const std::string& b, std::size_t& at) {
  while (at < b.size()) {
    if (b[at] == '#') {
      while (at < b.size() && b[at] != '\n' && b[at] != '\r') ++at;
    } else if (std::isspace(static_cast<unsigned char>(b[at]))) {
      ++at;
    } else {
      return;
    }
  }
}

// A decimal number of a PGM header or plain raster; `what` names it in errors.
long read_decimal(const std::string& b, std::size_t& at, const std::string& name, const std::string& what) {
  skip_space(b, at);
  if (at >= b.size()) throw std::invalid_argument(name + ": the PGM ends before its " + what + " (truncated)");
  if (!std::isdigit(static_cast<unsigned char>(b[at])))
    throw std::invalid_argument(name + ": malformed PGM: expected the " + what + " as a decimal number, got '" +
                                std::string(1, b[at]) + "'");
  long value = 0;
  while (at < b.size() && std::isdigit(static_cast<unsigned char>(b[at]))) {
    value = value * 10 + (b[at++] - '0');
    if (value > 1'000'000'000)
      throw std::invalid_argument(name + ": malformed PGM: the " + what + " is absurdly large");
  }
  return value;
}

MapImage decode_pgm(const std::string& b, const std::string& name, std::size_t max_cells) {
  const bool plain = b[1] == '2';
  std::size_t at = 2;
  if (at < b.size() && !std::isspace(static_cast<unsigned char>(b[at])) && b[at] != '#')
    throw std::invalid_argument(name + ": malformed PGM: no whitespace after the magic number");
  MapImage image;
  const long width = read_decimal(b, at, name, "width"), height = read_decimal(b, at, name, "height");
  const long maxval = read_decimal(b, at, name, "maxval");
  if (width < 1 || height < 1)
    throw std::invalid_argument(name + ": the PGM has no pixels (" + std::to_string(width) + " x " +
                                std::to_string(height) + ")");
  if (maxval < 1 || maxval > 65535)
    throw std::invalid_argument(name + ": PGM maxval " + std::to_string(maxval) + " is outside 1..65535");
  const double cells = static_cast<double>(width) * static_cast<double>(height);
  if (cells > static_cast<double>(max_cells))
    throw std::invalid_argument(name + ": " + std::to_string(width) + " x " + std::to_string(height) +
                                " pixels exceed the limit of " + std::to_string(max_cells) +
                                " cells; crop the map or save it at a coarser resolution");
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.maxval = static_cast<int>(maxval);
  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (plain) {
    image.samples.reserve(std::min<std::size_t>(count, b.size()));
    for (std::size_t i = 0; i < count; ++i) {
      const long v = read_decimal(b, at, name, "pixel " + std::to_string(i) + " of " + std::to_string(count));
      if (v > maxval)
        throw std::invalid_argument(name + ": pixel " + std::to_string(i) + " is " + std::to_string(v) +
                                    ", above maxval " + std::to_string(maxval));
      image.samples.push_back(static_cast<std::uint16_t>(v));
    }
    return image;
  }
  if (at >= b.size() || !std::isspace(static_cast<unsigned char>(b[at])))
    throw std::invalid_argument(name + ": malformed PGM: expected one whitespace character after maxval");
  ++at;  // exactly one whitespace character, then the raster
  const std::size_t bytes_per = maxval > 255 ? 2 : 1;
  if ((b.size() - at) / bytes_per < count)
    throw std::invalid_argument(name + ": the PGM ends after " + std::to_string((b.size() - at) / bytes_per) +
                                " of its " + std::to_string(count) + " pixels (truncated)");
  image.samples.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at + i * bytes_per);
    const unsigned v = bytes_per == 2 ? (p[0] << 8) | p[1] : p[0];
    if (v > static_cast<unsigned>(maxval))
      throw std::invalid_argument(name + ": pixel " + std::to_string(i) + " is " + std::to_string(v) +
                                  ", above maxval " + std::to_string(maxval));
    image.samples[i] = static_cast<std::uint16_t>(v);
  }
  return image;
}

// Refuses an image whose header announces more than max_cells pixels, from the file's first bytes, before the
// rest is read (a header cut short is left to the full decode, which names it).
void check_size_from_header(const std::string& prefix, const std::string& name, std::size_t max_cells) {
  long width = 0, height = 0;
  if (prefix.size() >= 24 && prefix.compare(1, 3, "PNG") == 0 && prefix.compare(12, 4, "IHDR") == 0) {
    const auto be32 = [&](std::size_t at) {
      const auto* p = reinterpret_cast<const unsigned char*>(prefix.data() + at);
      return (static_cast<long>(p[0]) << 24) | (p[1] << 16) | (p[2] << 8) | p[3];
    };
    width = be32(16), height = be32(20);
  } else if (prefix.size() >= 2 && prefix[0] == 'P' && (prefix[1] == '5' || prefix[1] == '2')) {
    try {
      std::size_t at = 2;
      width = read_decimal(prefix, at, name, "width");
      height = read_decimal(prefix, at, name, "height");
    } catch (const std::invalid_argument&) {
      return;
    }
  }
  if (static_cast<double>(width) * static_cast<double>(height) > static_cast<double>(max_cells))
    throw std::invalid_argument(name + ": " + std::to_string(width) + " x " + std::to_string(height) +
                                " pixels exceed the limit of " + std::to_string(max_cells) +
                                " cells; crop the map or save it at a coarser resolution");
}

// The YAML's document, refused unless every key is map_server's, once.
YAML::Node load_map_yaml(const std::string& text, const std::string& file) {
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail(file, YAML::Node(), "", "malformed YAML at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!doc.IsMap())
    fail(file, doc, "",
         "expected map_server's keys (image, resolution, origin, negate, occupied_thresh, free_thresh, mode)");
  const std::vector<std::string> known(std::begin(kKnownKeys), std::end(kKnownKeys));
  std::set<std::string> seen;
  for (const auto& entry : doc) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : "";
    if (!seen.insert(key).second) fail(file, entry.first, key, "duplicate key; keep one");
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      const std::string nearest = nearest_name(key, known);
      fail(file, entry.first, key,
           "unknown key" + (nearest.empty() ? std::string() : "; did you mean '" + nearest + "'?") +
               " (map_server reads image, resolution, origin, negate, occupied_thresh, free_thresh, mode)");
    }
  }
  return doc;
}

// doc[key], refused when missing or without a value.
YAML::Node required(const YAML::Node& doc, const std::string& file, const char* key) {
  const YAML::Node node = doc[key];
  if (!node)
    fail(file, doc, key, std::string("required key is missing (map_server requires it too); add ") + key + ": ...");
  if (node.IsNull()) fail(file, node, key, "has no value");
  return node;
}

// resolution and origin: where the grid lies.
void read_placement(const YAML::Node& doc, const std::string& file, MapMetadata& m) {
  const YAML::Node resolution = required(doc, file, "resolution");
  m.resolution_m = number(file, resolution, "resolution");
  if (!(std::isfinite(m.resolution_m) && m.resolution_m > 0 && m.resolution_m <= 100))
    fail(file, resolution, "resolution",
         "must be a finite number in (0, 100] m per cell, got " + resolution.Scalar() + "; e.g. resolution: 0.05");

  const YAML::Node origin = required(doc, file, "origin");
  if (!origin.IsSequence() || origin.size() != 3)
    fail(file, origin, "origin", "expected [x, y, yaw] (m, m, rad), e.g. origin: [-10.0, -10.0, 0.0]");
  const double o[3] = {number(file, origin[0], "origin"), number(file, origin[1], "origin"),
                       number(file, origin[2], "origin")};
  if (!(std::isfinite(o[0]) && std::isfinite(o[1]) && std::isfinite(o[2])) || std::abs(o[0]) > 1e6 ||
      std::abs(o[1]) > 1e6)
    fail(file, origin, "origin",
         "x and y must be finite and within 1e6 m, yaw finite; got [" + origin[0].Scalar() + ", " + origin[1].Scalar() +
             ", " + origin[2].Scalar() + "]");
  m.origin_x_m = o[0], m.origin_y_m = o[1], m.origin_yaw_rad = o[2];
}

// negate, occupied_thresh and free_thresh: how pixels become occupancy.
void read_thresholds(const YAML::Node& doc, const std::string& file, MapMetadata& m) {
  const YAML::Node negate = required(doc, file, "negate");
  try {
    m.negate = negate.as<int>() != 0;  // map_server reads an integer, then a boolean
  } catch (const YAML::Exception&) {
    try {
      m.negate = negate.as<bool>();
    } catch (const YAML::Exception&) {
      fail(file, negate, "negate",
           "expected 0, 1, true or false, got '" + (negate.IsScalar() ? negate.Scalar() : std::string("a list")) + "'");
    }
  }
  const YAML::Node occupied = required(doc, file, "occupied_thresh"), free = required(doc, file, "free_thresh");
  m.occupied_thresh = number(file, occupied, "occupied_thresh");
  m.free_thresh = number(file, free, "free_thresh");
  if (!(std::isfinite(m.occupied_thresh) && m.occupied_thresh > 0 && m.occupied_thresh <= 1))
    fail(file, occupied, "occupied_thresh", "must lie in (0, 1], got " + occupied.Scalar() + "; map_saver writes 0.65");
  if (!(std::isfinite(m.free_thresh) && m.free_thresh >= 0 && m.free_thresh < m.occupied_thresh))
    fail(file, free, "free_thresh",
         "must lie in [0, occupied_thresh), got " + free.Scalar() + "; map_saver writes 0.25");
}

// mode, when given: trinary, scale or raw.
void read_mode(const YAML::Node& doc, const std::string& file, MapMetadata& m) {
  if (const YAML::Node mode = doc["mode"]) {
    const std::string name = mode.IsScalar() ? mode.Scalar() : "";
    if (name == "trinary") m.mode = MapMode::kTrinary;
    else if (name == "scale") m.mode = MapMode::kScale;
    else if (name == "raw") m.mode = MapMode::kRaw;
    else {
      const std::string nearest = nearest_name(name, {"trinary", "scale", "raw"});
      fail(file, mode, "mode",
           "unknown mode '" + name + "'" + (nearest.empty() ? "" : "; did you mean '" + nearest + "'?") +
               " (trinary, scale or raw)");
    }
  }
}

}  // namespace

const char* to_string(MapMode mode) {
  switch (mode) {
    case MapMode::kTrinary: return "trinary";
    case MapMode::kScale: return "scale";
    case MapMode::kRaw: return "raw";
  }
  return "?";
}

MapMetadata parse_map_yaml(const std::string& text, const std::string& file, const std::string& yaml_dir) {
  const YAML::Node doc = load_map_yaml(text, file);
  MapMetadata m;
  const YAML::Node image = required(doc, file, "image");
  if (!image.IsScalar() || image.Scalar().empty())
    fail(file, image, "image", "expected the image file's name (PGM or PNG)");
  m.image = image.Scalar();
  m.image_path = std::filesystem::path(m.image).is_absolute()
                     ? m.image
                     : (std::filesystem::path(yaml_dir) / m.image).lexically_normal().string();

  read_placement(doc, file, m);
  read_thresholds(doc, file, m);
  read_mode(doc, file, m);
  return m;
}

MapImage decode_map_image(const std::string& bytes, const std::string& name, std::size_t max_cells) {
  if (bytes.size() >= 2 && bytes[0] == 'P' && (bytes[1] == '5' || bytes[1] == '2'))
    return decode_pgm(bytes, name, max_cells);
  if (bytes.size() >= 4 && bytes.compare(1, 3, "PNG") == 0) {
    PngImage png;
    try {
      png = decode_png(bytes, name, max_cells);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(std::string(e.what()) + "; re-save it with an image editor or map_saver");
    }
    MapImage image;
    image.width = png.width;
    image.height = png.height;
    image.channels = png.channels;
    image.maxval = png.bit_depth == 16 ? 65535 : 255;
    image.samples = std::move(png.samples);
    return image;
  }
  std::string magic;
  for (std::size_t i = 0; i < std::min<std::size_t>(bytes.size(), 2); ++i)
    magic += std::isprint(static_cast<unsigned char>(bytes[i])) ? bytes[i] : '?';
  throw std::invalid_argument(name + ": not a PGM (P5 or P2) or PNG image (it starts '" + magic +
                              "'); save the map as PGM or PNG");
}

Nav2Map to_occupancy(const MapImage& image, const MapMetadata& meta) {
  Nav2Map map;
  map.meta = meta;
  map.width = image.width;
  map.height = image.height;
  map.data.assign(static_cast<std::size_t>(image.width) * image.height, -1);
  const bool alpha = image.channels == 2 || image.channels == 4;
  const int colour = alpha ? image.channels - 1 : image.channels;  // 1 grey or 3 RGB
  const double maxval = image.maxval;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::uint16_t* px = image.samples.data() + (static_cast<std::size_t>(y) * image.width + x) * image.channels;
      // Grey stands for three equal channels, as the image library map_server uses reads it.
      double sum = colour == 1 ? 3.0 * px[0] : static_cast<double>(px[0]) + px[1] + px[2];
      int n = 3;
      const double a = alpha ? px[image.channels - 1] : maxval;
      if (meta.mode == MapMode::kTrinary && alpha) sum += a, n = 4;
      const double shade = sum / n / maxval;
      const double occ = meta.negate ? shade : 1.0 - shade;
      std::int8_t cell = -1;
      switch (meta.mode) {
        case MapMode::kTrinary: cell = meta.occupied_thresh < occ ? 100 : occ < meta.free_thresh ? 0 : -1; break;
        case MapMode::kScale:
          if (a != maxval) cell = -1;
          else if (meta.occupied_thresh < occ) cell = 100;
          else if (occ < meta.free_thresh) cell = 0;
          else
            cell = static_cast<std::int8_t>(
                std::rint((occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh) * 100.0));
          break;
        case MapMode::kRaw: {
          const double percent = std::round(shade * 255);
          cell = percent >= 0 && percent <= 100 ? static_cast<std::int8_t>(percent) : -1;
          break;
        }
      }
      map.data[static_cast<std::size_t>(image.height - 1 - y) * image.width + x] = cell;
    }
  return map;
}

Nav2Map load_nav2_map(const std::string& yaml_path, std::size_t max_cells) {
  std::ifstream yaml(yaml_path, std::ios::binary);
  if (!yaml) throw std::invalid_argument(yaml_path + ": cannot read the map's YAML file; check the path");
  const std::string text((std::istreambuf_iterator<char>(yaml)), std::istreambuf_iterator<char>());
  const MapMetadata meta = parse_map_yaml(text, yaml_path, std::filesystem::path(yaml_path).parent_path().string());
  std::ifstream in(meta.image_path, std::ios::binary);
  if (!in || std::filesystem::is_directory(meta.image_path))
    throw std::invalid_argument(
        yaml_path + ": image: cannot read '" + meta.image_path +
        "' (a relative image path is resolved against the YAML's folder); fix the path or add the file");
  std::string bytes(4096, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  check_size_from_header(bytes, meta.image_path, max_cells);
  bytes.append((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return to_occupancy(decode_map_image(bytes, meta.image_path, max_cells), meta);
}

}  // namespace stvl::worldgen
