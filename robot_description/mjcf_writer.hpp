#pragma once
// The one MJCF text writer, for the robot written from a URDF (urdf_mjcf.hpp) and the worlds worldgen/ builds:
// one element per line, indented per depth, attribute values escaped as tinyxml2 escapes them, comments, and the
// two ways numbers are written (the shortest text that reads back the same double; fixed decimals). The same calls
// always give the same bytes.
//   MjcfWriter xml(4);
//   xml.open("mujoco");
//   xml.attribute("model", "robot");
//   xml.element("option", {{"timestep", "0.002"}});
//   xml.close();  // xml.text(): <mujoco model="robot">\n    <option timestep="0.002"/>\n</mujoco>\n
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace stvl::robot_description {

// The shortest text that reads back to the same double (std::to_chars); -0 is written as 0.
std::string shortest_number(double value);
// `values` as shortest_number, separated by single spaces.
std::string shortest_numbers(std::initializer_list<double> values);

// `value` with `decimals` digits after the point (printf's rounding), "-0.000" written as "0.000".
std::string fixed(double value, int decimals = 4);
// `values` as fixed, separated by single spaces.
std::string fixed_numbers(const std::vector<double>& values, int decimals);

// `text` fit for an XML comment, which may not hold "--": each "--" becomes "- ".
std::string comment_text(std::string text);

// Elements one per line, `indent` spaces per depth: `<name a="v"/>` when nothing follows inside it, else
// `<name a="v">`, its children, `</name>`. Attribute values are escaped (" & ' < > as entities).
class MjcfWriter {
 public:
  explicit MjcfWriter(int indent = 2) : indent_(indent) {}

  // Starts element `name`; attributes follow until a child, a comment, end_attributes() or close().
  void open(const std::string& name);
  void attribute(const std::string& key, const std::string& value);
  // Ends the start tag: the element gets an end tag even if no child follows.
  void end_attributes();
  // Ends the innermost open element.
  void close();
  // An element without children.
  void element(const std::string& name, std::initializer_list<std::pair<const char*, std::string>> attributes);
  // <!-- text --> on a line of its own (text through comment_text).
  void comment(const std::string& text);
  // A comment over several lines: <!--, each line of `text` one level deeper (empty lines left empty), -->.
  void comment_block(const std::string& text);

  // What was written so far; whole once every element is closed.
  const std::string& text() const { return text_; }

 private:
  void start_line();

  int indent_;
  std::vector<std::string> open_;  // the elements not yet closed, outermost first
  bool start_tag_open_ = false;    // the innermost element's start tag still takes attributes
  std::string text_;
};

}  // namespace stvl::robot_description
