// ParamReader: every field read with an error naming the file and its JSON path; unknown and unused
// keys are errors, never silent defaults.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "test_util.h"
#include "weft/core/params.h"

using namespace weft;
using weft::testing::error_of;
using json = nlohmann::json;

namespace {

// The error of 'read' on a reader of j, in file "scene.json" at path "materials.seat".
std::string error_reading(const json& j, const std::function<void(ParamReader&)>& read) {
  return error_of([&] {
    ParamReader r(j, "scene.json", "materials.seat");
    read(r);
    r.finish();
  });
}

// The message starts with the file and the full path of the field, then says what is wrong.
void expect_error(const std::string& msg, const std::string& field, const std::string& what) {
  EXPECT_EQ(msg.rfind("scene.json: field '" + field + "': ", 0), 0u) << msg;
  EXPECT_NE(msg.find(what), std::string::npos) << msg;
}

}  // namespace

TEST(ParamReader, UnknownKeysAreRejectedWithTheirPathAndTheKnownKeys) {
  const json j = {{"alpha", 0.2}, {"reflectance", 0.5}, {"alhpa", 0.3}};
  const std::string msg = error_reading(j, [](ParamReader& r) {
    r.number("alpha", 0, 1);
    r.rgb("reflectance", Rgb(1.0), 0, 1);
  });
  expect_error(msg, "materials.seat.alhpa", "unknown key");
  EXPECT_NE(msg.find("known here: alpha, reflectance"), std::string::npos) << msg;
  // An object that reads nothing says so.
  expect_error(error_reading({{"x", 1}}, [](ParamReader&) {}), "materials.seat.x",
               "this object takes no keys");
  // Keys asked for but absent are fine; so is asking with has() alone.
  EXPECT_EQ(error_reading({{"flag", true}},
                          [](ParamReader& r) {
                            EXPECT_TRUE(r.has("flag"));
                            EXPECT_FALSE(r.has("other"));
                          }),
            "");
}

TEST(ParamReader, RejectUnusedNamesTheKeyAndTheReason) {
  const json j = {{"seed", 3}};
  expect_error(error_reading(j, [](ParamReader& r) { r.reject_unused("seed", "has no effect"); }),
               "materials.seat.seed", "has no effect");
  EXPECT_EQ(error_reading(json::object(),
                          [](ParamReader& r) { r.reject_unused("seed", "has no effect"); }),
            "");
}

TEST(ParamReader, IntegersAndCountsAcceptIntegralNumbersOnly) {
  const json j = {{"a", 1e5}, {"b", 0.5}, {"c", 100000}, {"d", -2}, {"e", 7.0}};
  ParamReader r(j, "scene.json", "materials.seat");
  EXPECT_EQ(r.count("a", 1, 1000000), 100000u);  // 1e5 is the integer 100000
  EXPECT_EQ(r.integer("a", 0, 1000000), 100000);
  EXPECT_EQ(r.count("c", 1, 1000000), 100000u);
  EXPECT_EQ(r.integer("d", -5, 5), -2);
  EXPECT_EQ(r.count("e", 0, 10), 7u);
  expect_error(error_of([&] { r.count("b", 0, 10); }), "materials.seat.b",
               "must be an integer, got 0.5");
  expect_error(error_of([&] { r.integer("b", 0, 10); }), "materials.seat.b", "must be an integer");
  expect_error(error_of([&] { r.count("d", 0, 10); }), "materials.seat.d", "must lie in [0, 10]");
  expect_error(error_of([&] { r.count("c", 1, 99999); }), "materials.seat.c",
               "must lie in [1, 99999], got 100000");
  expect_error(error_of([&] { r.integer("d", 0, 5); }), "materials.seat.d", "got -2");
  // Fallbacks only when absent.
  EXPECT_EQ(r.count("missing", 42, 0, 100), 42u);
  EXPECT_EQ(r.integer("missing", -1, -5, 5), -1);
  expect_error(error_of([&] { r.count("absent", 0, 10); }), "materials.seat.absent", "is required");
}

// An array of counts: its length is bounded before any element is read, and each element is
// checked as count() checks one, so 2^64 or 1e30 (beyond every uint64_t) is refused, never cast.
TEST(ParamReader, CountsAreAnArrayOfCheckedCounts) {
  const json j = {{"ok", {0, 1e5, 7.0, 18446744073709551615u}},
                  {"long", {1, 2, 3}},
                  {"frac", {1, 2.5}},
                  {"huge", {1, 1e30}},
                  {"two64", {18446744073709551616.0}},
                  {"neg", {-1}},
                  {"text", {"1"}},
                  {"scalar", 1}};
  ParamReader r(j, "scene.json", "");
  const uint64_t all = std::numeric_limits<uint64_t>::max();
  EXPECT_EQ(r.counts("ok", 4, 0, all),
            (std::vector<uint64_t>{0, 100000, 7, std::numeric_limits<uint64_t>::max()}));
  expect_error(error_of([&] { r.counts("long", 2, 0, 10); }), "long",
               "has 3 entries, at most 2 allowed");
  expect_error(error_of([&] { r.counts("frac", 2, 0, 10); }), "frac[1]", "must be an integer");
  expect_error(error_of([&] { r.counts("huge", 2, 0, all); }), "huge[1]", "must lie in");
  expect_error(error_of([&] { r.counts("two64", 2, 0, all); }), "two64[0]", "must lie in");
  expect_error(error_of([&] { r.counts("neg", 2, 0, 10); }), "neg[0]", "must lie in [0, 10]");
  expect_error(error_of([&] { r.counts("text", 2, 0, 10); }), "text[0]", "must be a number");
  expect_error(error_of([&] { r.counts("scalar", 2, 0, 10); }), "scalar",
               "must be an array of whole numbers");
}

TEST(ParamReader, NumbersAreFiniteAndInRange) {
  const json j = {{"x", 2.5}, {"s", "2.5"}, {"big", 1e300}};
  ParamReader r(j, "scene.json", "materials.seat");
  EXPECT_EQ(r.number("x", 0, 3), 2.5);
  EXPECT_EQ(r.number("x", 9.0, 0, 3), 2.5);
  EXPECT_EQ(r.number("none", 9.0, 0, 3), 9.0);
  expect_error(error_of([&] { r.number("x", 0, 1); }), "materials.seat.x",
               "must lie in [0, 1], got 2.5");
  expect_error(error_of([&] { r.number("s", 0, 3); }), "materials.seat.s", "must be a number");
  expect_error(error_of([&] { r.number("big", 0, 1); }), "materials.seat.big", "must lie in");
  // JSON has no NaN or infinity literal; the check still holds for values that arrive as such.
  const json nan = {{"v", std::nan("")}};
  ParamReader rn(nan, "scene.json", "materials.seat");
  expect_error(error_of([&] { rn.number("v", -1, 1); }), "materials.seat.v", "must be finite");
}

TEST(ParamReader, ColoursAreAGreyOrThreeComponents) {
  const json j = {{"grey", 0.5},
                  {"rgb", {0.1, 0.2, 0.3}},
                  {"two", {0.1, 0.2}},
                  {"high", {0.1, 2.0, 0.3}},
                  {"text", {0.1, "g", 0.3}}};
  ParamReader r(j, "scene.json", "materials.seat");
  EXPECT_EQ(r.rgb("grey", 0, 1), Rgb(0.5));
  EXPECT_EQ(r.rgb("rgb", 0, 1), Rgb(0.1, 0.2, 0.3));
  EXPECT_EQ(r.rgb("none", Rgb(0.7), 0, 1), Rgb(0.7));
  expect_error(error_of([&] { r.rgb("two", 0, 1); }), "materials.seat.two", "needs 3 components");
  expect_error(error_of([&] { r.rgb("high", 0, 1); }), "materials.seat.high[1]",
               "must lie in [0, 1], got 2");
  expect_error(error_of([&] { r.rgb("text", 0, 1); }), "materials.seat.text[1]",
               "must be a number");
}

TEST(ParamReader, NestedObjectsCarryTheirPath) {
  const json j = {{"roughness", {{"alpha", 0.3}, {"model", "ggx"}, {"extra", 1}}}};
  const std::string msg = error_reading(j, [](ParamReader& r) {
    ParamReader inner = r.object("roughness");
    EXPECT_EQ(inner.path(), "materials.seat.roughness");
    EXPECT_EQ(inner.file(), "scene.json");
    EXPECT_EQ(inner.field("alpha"), "materials.seat.roughness.alpha");
    EXPECT_EQ(inner.number("alpha", 0, 1), 0.3);
    EXPECT_EQ(inner.choice("model", "beckmann", {"beckmann", "ggx"}), "ggx");
    inner.finish();
  });
  expect_error(msg, "materials.seat.roughness.extra", "unknown key");
  // A nested value that is not an object, and a root that is not an object.
  expect_error(error_reading({{"roughness", 3}}, [](ParamReader& r) { r.object("roughness"); }),
               "materials.seat.roughness", "must be a JSON object");
  const std::string root = error_of([] { ParamReader(json::array(), "a.json", ""); });
  EXPECT_EQ(root, "a.json: field '(root)': must be a JSON object");
  // At the root, paths have no leading dot.
  ParamReader top(json::object(), "a.json", "");
  EXPECT_EQ(top.field("name"), "name");
}

TEST(ParamReader, StringsChoicesBooleansAndVectors) {
  const json j = {{"name", "seat"}, {"empty", ""},      {"mode", "fast"},    {"on", true},
                  {"flag", 1},      {"dir", {0, 3, 4}}, {"zero", {0, 0, 0}}, {"short", {1, 2}}};
  ParamReader r(j, "scene.json", "materials.seat");
  EXPECT_EQ(r.string("name"), "seat");
  EXPECT_EQ(r.string("none", "fallback"), "fallback");
  expect_error(error_of([&] { r.string("empty"); }), "materials.seat.empty", "must not be empty");
  EXPECT_EQ(r.string_or_empty("empty"), "");
  EXPECT_EQ(r.string_or_empty("name"), "seat");
  expect_error(error_of([&] { r.string_or_empty("flag"); }), "materials.seat.flag",
               "must be a string");
  expect_error(error_of([&] { r.string_or_empty("none"); }), "materials.seat.none", "is required");
  const std::string msg = error_of([&] { r.choice("mode", "mis", {"mis", "lights_only"}); });
  expect_error(msg, "materials.seat.mode", "unknown value 'fast' (valid: mis, lights_only)");
  EXPECT_TRUE(r.boolean("on", false));
  EXPECT_TRUE(r.boolean("none", true));
  expect_error(error_of([&] { r.boolean("flag", false); }), "materials.seat.flag",
               "must be true or false");
  EXPECT_EQ(r.vec3("dir"), Vec3(0, 3, 4));
  EXPECT_NEAR(length(r.unit_vec3("dir") - Vec3(0, 0.6, 0.8)), 0.0, 1e-15);
  expect_error(error_of([&] { r.unit_vec3("zero"); }), "materials.seat.zero", "zero vector");
  expect_error(error_of([&] { r.vec3("short"); }), "materials.seat.short",
               "must be an array of 3 numbers");
}

// Bad input: deeply nested JSON segfaulted (unbounded recursion). The depth is bounded
// before the parser sees the text; the error names the file and where the limit was passed.
TEST(ParseJson, DeeplyNestedJsonIsRefusedBeforeParsing) {
  const std::string deep(100000, '[');  // the hostile input of the issue: 10^5 open arrays
  const std::string msg = error_of([&] { parse_json(deep, "deep.json"); });
  EXPECT_EQ(msg.rfind("deep.json: JSON nested deeper than 128", 0), 0u) << msg;
  EXPECT_NE(msg.find("line 1, column 129"), std::string::npos) << msg;
  // Exactly the limit parses; one more level does not.
  const std::string at_limit = std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']');
  EXPECT_EQ(error_of([&] { parse_json(at_limit, "ok.json"); }), "");
  const std::string over = "[" + at_limit + "]";
  EXPECT_NE(error_of([&] { parse_json(over, "over.json"); }).find("nested deeper"),
            std::string::npos);
  // Brackets inside strings (escaped quotes included) do not count.
  const std::string in_string = "{\"a\": \"\\\"" + std::string(1000, '[') + "\"}";
  EXPECT_EQ(parse_json(in_string, "s.json")["a"].get<std::string>().size(), 1001u);
}

// Bad input: `1e400` in a scene was an "internal error" (nlohmann's out_of_range escaped); it is a
// clear error naming the file and the JSON path of the number.
TEST(ParseJson, NumberOutOfRangeNamesFileAndField) {
  const std::string text = R"({"lights": [{"type": "parallel"}, {"irradiance": 1e400}]})";
  const std::string msg = error_of([&] { parse_json(text, "scene.json"); });
  EXPECT_EQ(msg.rfind("scene.json: field 'lights[1].irradiance': number 1e400 is out of range", 0),
            0u)
      << msg;
  const std::string neg = error_of([&] { parse_json(R"({"a": {"b": [1, -1e999]}})", "x.json"); });
  EXPECT_EQ(neg.rfind("x.json: field 'a.b[1]': number -1e999", 0), 0u) << neg;
}

TEST(ParseJson, SyntaxErrorsNameFileAndFieldAndValidJsonRoundTrips) {
  const std::string msg = error_of([&] { parse_json(R"({"render": {"spp": 4,}})", "s.json"); });
  EXPECT_EQ(msg.rfind("s.json: field 'render.spp': invalid JSON", 0), 0u) << msg;
  EXPECT_NE(error_of([&] { parse_json("{} trailing", "t.json"); }).find("invalid JSON"),
            std::string::npos);
  const json j = parse_json(
      R"({"a": [1, 2.5, "x", true, null, {"b": -3}], "c": 18446744073709551615})", "ok.json");
  EXPECT_EQ(
      j, json::parse(R"({"a": [1, 2.5, "x", true, null, {"b": -3}], "c": 18446744073709551615})"));
}
