#include "robot_description/mjcf_writer.hpp"

#include <charconv>
#include <cstdio>
#include <sstream>

namespace stvl::robot_description {

std::string shortest_number(double value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value == 0.0 ? 0.0 : value).ptr;
  return std::string(buffer, end);
}

std::string shortest_numbers(std::initializer_list<double> values) {
  std::string text;
  for (double v : values) text += (text.empty() ? "" : " ") + shortest_number(v);
  return text;
}

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  std::string out = text;
  if (out.find_first_not_of("-0.") == std::string::npos && out[0] == '-') out.erase(0, 1);
  return out;
}

std::string fixed_numbers(const std::vector<double>& values, int decimals) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : " ") + fixed(v, decimals);
  return out;
}

std::string comment_text(std::string text) {
  for (std::size_t at = text.find("--"); at != std::string::npos; at = text.find("--", at)) text.replace(at, 2, "- ");
  return text;
}

void MjcfWriter::start_line() {
  end_attributes();
  text_.append(indent_ * open_.size(), ' ');
}

void MjcfWriter::open(const std::string& name) {
  start_line();
  text_ += "<" + name;
  open_.push_back(name);
  start_tag_open_ = true;
}

void MjcfWriter::attribute(const std::string& key, const std::string& value) {
  text_ += " " + key + "=\"";
  for (char c : value) {
    switch (c) {
      case '"': text_ += "&quot;"; break;
      case '&': text_ += "&amp;"; break;
      case '\'': text_ += "&apos;"; break;
      case '<': text_ += "&lt;"; break;
      case '>': text_ += "&gt;"; break;
      default: text_ += c;
    }
  }
  text_ += "\"";
}

void MjcfWriter::end_attributes() {
  if (!start_tag_open_) return;
  text_ += ">\n";
  start_tag_open_ = false;
}

void MjcfWriter::close() {
  const std::string name = open_.back();
  if (start_tag_open_) {
    open_.pop_back();
    text_ += "/>\n";
    start_tag_open_ = false;
    return;
  }
  open_.pop_back();
  text_.append(indent_ * open_.size(), ' ');
  text_ += "</" + name + ">\n";
}

void MjcfWriter::element(const std::string& name,
                         std::initializer_list<std::pair<const char*, std::string>> attributes) {
  open(name);
  for (const auto& [key, value] : attributes) attribute(key, value);
  close();
}

void MjcfWriter::comment(const std::string& text) {
  start_line();
  text_ += "<!-- " + comment_text(text) + " -->\n";
}

void MjcfWriter::comment_block(const std::string& text) {
  start_line();
  text_ += "<!--\n";
  const std::string deeper(indent_ * (open_.size() + 1), ' ');
  std::istringstream lines(comment_text(text));
  for (std::string line; std::getline(lines, line);) text_ += (line.empty() ? "" : deeper) + line + "\n";
  text_.append(indent_ * open_.size(), ' ');
  text_ += "-->\n";
}

}  // namespace stvl::robot_description
