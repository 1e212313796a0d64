#include "config/yaml_reader.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>
#include "tests/support/invalid_argument.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace stvl::config {
namespace {

namespace fs = std::filesystem;
using test::invalid_argument_of;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;

YamlMap root_of(const std::string& text) { return YamlMap(load_yaml_string(text, "t.yaml"), "t.yaml", ""); }

TEST(YamlReader, GetKeepsTheDefaultWhenAbsentAndReadsWhenPresent) {
  auto root = root_of("a: 2.5\nb: 7\nc: hello\nd: true\ne: [1, 2.5]\nf: [[1, 2], [3, 4]]\ng: [x, y]\n");
  double a = 0, absent = 9.0;
  int b = 0;
  std::string c;
  bool d = false;
  std::vector<double> e;
  std::vector<std::vector<double>> f;
  std::vector<std::string> g;
  root.get("a", a);
  root.get("absent", absent);
  root.get("b", b);
  root.get("c", c);
  root.get("d", d);
  root.get("e", e);
  root.get("f", f);
  root.get("g", g);
  EXPECT_DOUBLE_EQ(a, 2.5);
  EXPECT_DOUBLE_EQ(absent, 9.0);
  EXPECT_EQ(b, 7);
  EXPECT_EQ(c, "hello");
  EXPECT_TRUE(d);
  EXPECT_EQ(e, (std::vector<double>{1, 2.5}));
  EXPECT_EQ(f, (std::vector<std::vector<double>>{{1, 2}, {3, 4}}));
  EXPECT_EQ(g, (std::vector<std::string>{"x", "y"}));
  EXPECT_NO_THROW(root.finish());
}

TEST(YamlReader, RequireNamesTheMissingKeyAndTheMappingsLine) {
  auto root = root_of("top: 1\ninner:\n  x: 1\n");
  auto inner = root.map("inner");
  double y = 0;
  EXPECT_EQ(invalid_argument_of([&] { inner.require("y", y); }), "t.yaml:2: inner.y: required key is missing");
  EXPECT_THAT(invalid_argument_of([&] { root.map("missing"); }), HasSubstr("missing: required mapping is missing"));
}

TEST(YamlReader, UnknownKeysNameFileLineDottedKeyAndTheKnownKeys) {
  auto root = root_of("a: 1\nouter:\n  inner:\n    good: 1\n    typo: 2\n");
  double a = 0, good = 0;
  root.get("a", a);
  auto outer = root.map("outer");
  auto inner = outer.map("inner");
  inner.get("good", good);
  const std::string message = invalid_argument_of([&] { inner.finish(); });
  EXPECT_THAT(message, HasSubstr("t.yaml:5: outer.inner.typo: unknown key"));
  EXPECT_THAT(message, HasSubstr("known: good"));
  EXPECT_NO_THROW(outer.finish());
  EXPECT_NO_THROW(root.finish());
}

TEST(YamlReader, UnknownKeyInAListItemNamesItsIndex) {
  auto root = root_of("items:\n  - {x: 1}\n  - x: 2\n    y: 3\n");
  auto items = root.list_of_maps("items");
  ASSERT_EQ(items.size(), 2u);
  for (auto& item : items) {
    int x = 0;
    item.get("x", x);
  }
  EXPECT_NO_THROW(items[0].finish());
  EXPECT_THAT(invalid_argument_of([&] { items[1].finish(); }), HasSubstr("t.yaml:4: items[1].y: unknown key"));
}

TEST(YamlReader, WrongTypesNameTheKeyTheLineAndTheValue) {
  auto root = root_of("n: fast\nlist: 5\ni: 1.5\nu: -3\nb: maybe\ns: [a, b]\nnested: {v: [1, x]}\npoints: [1, 2]\n");
  double n = 0;
  std::vector<double> list;
  int i = 0;
  std::uint64_t u = 0;
  bool b = false;
  std::string s;
  std::vector<std::vector<double>> points;
  EXPECT_EQ(invalid_argument_of([&] { root.get("n", n); }), "t.yaml:1: n: expected a number, got 'fast'");
  EXPECT_EQ(invalid_argument_of([&] { root.get("list", list); }),
            "t.yaml:2: list: expected a list of numbers, got '5'");
  EXPECT_EQ(invalid_argument_of([&] { root.get("i", i); }), "t.yaml:3: i: expected an integer, got '1.5'");
  EXPECT_EQ(invalid_argument_of([&] { root.get("u", u); }), "t.yaml:4: u: expected a non-negative integer, got '-3'");
  EXPECT_EQ(invalid_argument_of([&] { root.get("b", b); }), "t.yaml:5: b: expected a boolean, got 'maybe'");
  EXPECT_EQ(invalid_argument_of([&] { root.get("s", s); }), "t.yaml:6: s: expected a string, got 'a list'");
  auto nested = root.map("nested");
  EXPECT_THAT(invalid_argument_of([&] { nested.get("v", list); }),
              HasSubstr("t.yaml:7: nested.v: expected a list of numbers"));
  EXPECT_THAT(invalid_argument_of([&] { root.get("points", points); }),
              HasSubstr("t.yaml:8: points: expected a list of number lists"));
  EXPECT_THAT(invalid_argument_of([&] { root.map("n"); }), HasSubstr("t.yaml:1: n: expected a mapping, got 'fast'"));
  EXPECT_THAT(invalid_argument_of([&] { root.list_of_maps("n"); }), HasSubstr("t.yaml:1: n: expected a list"));
  EXPECT_THAT(invalid_argument_of([&] { root.list_of_maps("list"); }), HasSubstr("list: expected a list"));
}

TEST(YamlReader, IntegersOutOfTheirRangeAreTypeErrors) {
  auto root = root_of("i: 3000000000\n");
  int i = 0;
  EXPECT_THAT(invalid_argument_of([&] { root.get("i", i); }), HasSubstr("t.yaml:1: i: expected an integer"));
}

TEST(YamlReader, AnEmptyValueIsAnErrorNotTheDefault) {
  auto root = root_of("a:\nb: ~\n");
  double a = 1.0;
  std::string b = "keep";
  EXPECT_THAT(invalid_argument_of([&] { root.get("a", a); }), HasSubstr("t.yaml:1: a: expected a number, got nothing"));
  EXPECT_THAT(invalid_argument_of([&] { root.require("b", b); }), HasSubstr("b: expected a string, got nothing"));
  EXPECT_DOUBLE_EQ(a, 1.0);
}

TEST(YamlReader, DuplicateKeysAreRejected) {
  EXPECT_EQ(invalid_argument_of([] { root_of("a: 1\nb: 2\na: 3\n"); }), "t.yaml:3: a: duplicate key");
  EXPECT_THAT(invalid_argument_of([] { root_of("m:\n  x: 1\n  x: 2\n").map("m"); }),
              HasSubstr("t.yaml:3: m.x: duplicate key"));
}

TEST(YamlReader, NonScalarKeysAreRejectedClearly) {
  EXPECT_THAT(invalid_argument_of([] { root_of("? [a, b]\n: 1\n"); }), HasSubstr("keys must be plain names"));
}

TEST(YamlReader, DocumentsThatAreNotMappingsAreRejected) {
  EXPECT_EQ(invalid_argument_of([] { root_of(""); }), "t.yaml:1: document: expected a mapping of keys to values");
  EXPECT_THAT(invalid_argument_of([] { root_of("just a string\n"); }),
              HasSubstr("t.yaml:1: document: expected a mapping"));
  EXPECT_THAT(invalid_argument_of([] { root_of("- a\n- b\n"); }), HasSubstr("document: expected a mapping"));
}

TEST(YamlReader, SyntaxErrorsNameTheLine) {
  EXPECT_THAT(invalid_argument_of([] { load_yaml_string("a: 1\nb: [1, 2\nc: 3\n", "s.yaml"); }),
              MatchesRegex("s\\.yaml:[2-4]: YAML syntax error: .*"));
  EXPECT_THAT(invalid_argument_of([] { load_yaml_string("a: 1\nb: 2\n  c: 3\n", "s.yaml"); }),
              MatchesRegex("s\\.yaml:3: YAML syntax error: .*"));
  EXPECT_THAT(invalid_argument_of([] { load_yaml_string("a: 1\n\tb: 2\n", "s.yaml"); }),
              MatchesRegex("s\\.yaml:2: YAML syntax error: .*"));
}

class YamlFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("stvl_yaml_reader_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  fs::path dir_;
};

YAML::Node with_sets(const std::string& text, const std::vector<std::string>& sets) {
  YAML::Node node = load_yaml_string(text, "t.yaml");
  for (const auto& s : sets) set_yaml_path(node, s);
  return node;
}

TEST(YamlSet, ReplacesAndAddsValuesWithTheirYamlTypes) {
  const YAML::Node n = with_sets("a: {b: 1, c: keep}\nl: [{x: 1}, {x: 2}]\n",
                                 {"a.b=0.25", "a.d=true", "new.deep.key=[[0, 0], [8, 0]]", "l[1].x=7", "top=text"});
  EXPECT_DOUBLE_EQ(n["a"]["b"].as<double>(), 0.25);
  EXPECT_EQ(n["a"]["c"].as<std::string>(), "keep");  // the rest of the mapping untouched
  EXPECT_TRUE(n["a"]["d"].as<bool>());
  EXPECT_DOUBLE_EQ(n["new"]["deep"]["key"][1][0].as<double>(), 8.0);
  EXPECT_EQ(n["l"][0]["x"].as<int>(), 1);
  EXPECT_EQ(n["l"][1]["x"].as<int>(), 7);
  EXPECT_EQ(n["top"].as<std::string>(), "text");
  // A whole list item can be replaced too.
  EXPECT_EQ(with_sets("l: [1, 2]\n", {"l[0]=5"})["l"][0].as<int>(), 5);
}

TEST(YamlSet, MalformedAssignmentsAndPathsNameTheAssignment) {
  const auto error = [](const std::string& assignment) {
    return invalid_argument_of([&] { with_sets("a: {b: 1}\nl: [1, 2]\n", {assignment}); });
  };
  EXPECT_EQ(error("a.b"), "--set a.b: expected KEY=VALUE");
  EXPECT_EQ(error("=1"), "--set =1: expected KEY=VALUE");
  EXPECT_EQ(error("a..b=1"), "--set a..b=1: malformed key 'a..b'");
  EXPECT_EQ(error("a.b.c=1"), "--set a.b.c=1: a.b.c: its parent holds '1', not a mapping");
  EXPECT_EQ(error("l[2]=1"), "--set l[2]=1: l[2]: the list has 2 items");
  EXPECT_EQ(error("a[0]=1"), "--set a[0]=1: a: not a list");
  EXPECT_EQ(error("l[x]=1"), "--set l[x]=1: malformed index in 'l[x]'");
  EXPECT_EQ(error("m[0].k=1"), "--set m[0].k=1: m: no such list");
  EXPECT_THAT(error("a.b={x: 1"), HasSubstr("--set a.b={x: 1: the value is not YAML"));
}

TEST_F(YamlFile, LoadsAFile) {
  const std::string path = write("ok.yaml", "a: 1\n");
  EXPECT_EQ(load_yaml_file(path)["a"].as<int>(), 1);
}

TEST_F(YamlFile, MissingFilesDirectoriesAndDevicesNameThePath) {
  const std::string missing = (dir_ / "nope.yaml").string();
  EXPECT_EQ(invalid_argument_of([&] { load_yaml_file(missing); }), missing + ": no such file");
  EXPECT_EQ(invalid_argument_of([&] { load_yaml_file(dir_.string()); }), dir_.string() + ": not a regular file");
  EXPECT_EQ(invalid_argument_of([&] { load_yaml_file("/dev/null"); }), "/dev/null: not a regular file");
}

TEST_F(YamlFile, SyntaxErrorsNameTheFileAndLine) {
  const std::string path = write("bad.yaml", "a: 1\nb: 2\nc: {x: 1\n");
  EXPECT_THAT(invalid_argument_of([&] { load_yaml_file(path); }),
              MatchesRegex(".*bad\\.yaml:[34]: YAML syntax error: .*"));
}

}  // namespace
}  // namespace stvl::config
