// robot_description/mjcf_writer.hpp: the MJCF writer of robot.xml (laid out as tinyxml2's XMLPrinter laid it out
// before, byte for byte) and of worldgen's worlds, and its numbers.
#include <gtest/gtest.h>

#include <string>

#include <tinyxml2.h>

#include "robot_description/mjcf_writer.hpp"

namespace stvl::robot_description {
namespace {

TEST(MjcfWriter, LaysOutElementsAsTinyxml2sPrinter) {
  const std::string odd = "a \"quoted\" & <tagged> 'name' \t\xc3\xa9";
  tinyxml2::XMLPrinter printer;
  MjcfWriter writer(4);
  printer.OpenElement("mujoco");
  writer.open("mujoco");
  printer.PushAttribute("model", odd.c_str());
  writer.attribute("model", odd);
  printer.OpenElement("asset");
  writer.open("asset");
  printer.OpenElement("mesh");
  writer.open("mesh");
  printer.PushAttribute("file", "a.stl");
  writer.attribute("file", "a.stl");
  printer.CloseElement();
  writer.close();
  printer.CloseElement();
  writer.close();
  printer.OpenElement("worldbody");
  writer.open("worldbody");
  printer.OpenElement("body");
  writer.open("body");
  printer.OpenElement("geom");
  printer.PushAttribute("size", "0.1 0.2");
  printer.CloseElement();
  writer.element("geom", {{"size", "0.1 0.2"}});
  printer.CloseElement();
  writer.close();
  printer.CloseElement();
  writer.close();
  printer.CloseElement();
  writer.close();
  EXPECT_EQ(writer.text(), std::string(printer.CStr()));
}

TEST(MjcfWriter, CommentsAndElementsThatKeepTheirEndTag) {
  MjcfWriter xml(2);
  xml.open("mujoco");
  xml.attribute("model", "m");
  xml.comment_block("first -- line\n\nthird");
  xml.comment("one -- line");
  xml.open("body");
  xml.attribute("name", "empty");
  xml.end_attributes();
  xml.close();
  xml.close();
  EXPECT_EQ(xml.text(),
            "<mujoco model=\"m\">\n"
            "  <!--\n"
            "    first -  line\n"
            "\n"
            "    third\n"
            "  -->\n"
            "  <!-- one -  line -->\n"
            "  <body name=\"empty\">\n"
            "  </body>\n"
            "</mujoco>\n");
}

TEST(MjcfNumbers, ShortestReadsBackAndFixedHasNoNegativeZero) {
  EXPECT_EQ(shortest_number(-0.0), "0");
  EXPECT_EQ(shortest_number(0.1), "0.1");
  EXPECT_EQ(shortest_number(1e-7), "1e-07");
  EXPECT_EQ(shortest_numbers({1.5, -2, 0}), "1.5 -2 0");
  EXPECT_EQ(fixed(-0.0001, 3), "0.000");
  EXPECT_EQ(fixed(-0.0006, 3), "-0.001");
  EXPECT_EQ(fixed(2.0), "2.0000");
  EXPECT_EQ(fixed_numbers({1, -0.00001, 2.5}, 2), "1.00 0.00 2.50");
  EXPECT_EQ(comment_text("a--b---c"), "a- b- -c");
}

}  // namespace
}  // namespace stvl::robot_description
