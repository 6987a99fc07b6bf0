#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "softrne/io/robot_json.hpp"
#include "temp_files.hpp"

namespace sio = softrne::io;
using nlohmann::json;

namespace {

const char* const kArmA = SOFTRNE_DATA_DIR "/arm-a-1/robot.json";

using softrne_test::slurp;
using softrne_test::temp_path;

/// Exact (bitwise for doubles) equality of two robot descriptions.
void expect_same(const sio::RobotSpec& a, const sio::RobotSpec& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.gravity, b.gravity);
  ASSERT_EQ(a.segments.size(), b.segments.size());
  for (std::size_t i = 0; i < a.segments.size(); ++i) {
    SCOPED_TRACE("segment " + std::to_string(i));
    ASSERT_EQ(a.segments[i].index(), b.segments[i].index());
    if (const auto* x = std::get_if<sio::CCJointSpec>(&a.segments[i])) {
      const auto& y = std::get<sio::CCJointSpec>(b.segments[i]);
      EXPECT_EQ(x->name, y.name);
      EXPECT_EQ(x->mass, y.mass);
      EXPECT_EQ(x->height, y.height);
      EXPECT_EQ(x->diameter, y.diameter);
      EXPECT_EQ(x->chamber_distance, y.chamber_distance);
      EXPECT_EQ(x->chamber_radius, y.chamber_radius);
      EXPECT_EQ(x->stiffness, y.stiffness);
      EXPECT_EQ(x->damping, y.damping);
      ASSERT_EQ(x->pressure_to_torque.cols(), y.pressure_to_torque.cols());
      EXPECT_EQ(x->pressure_to_torque, y.pressure_to_torque);
      EXPECT_EQ(x->custom_pressure_map, y.custom_pressure_map);
      EXPECT_EQ(x->inertia_model, y.inertia_model);
      EXPECT_EQ(x->quadrature_points, y.quadrature_points);
    } else if (const auto* l = std::get_if<sio::RigidLinkSpec>(&a.segments[i])) {
      const auto& m = std::get<sio::RigidLinkSpec>(b.segments[i]);
      EXPECT_EQ(l->name, m.name);
      EXPECT_EQ(l->mass, m.mass);
      EXPECT_EQ(l->length, m.length);
      EXPECT_EQ(l->com, m.com);
      EXPECT_EQ(l->inertia, m.inertia);
    } else {
      const auto& r = std::get<sio::RevoluteJointSpec>(a.segments[i]);
      const auto& s = std::get<sio::RevoluteJointSpec>(b.segments[i]);
      EXPECT_EQ(r.name, s.name);
      EXPECT_EQ(r.axis, s.axis);
      EXPECT_EQ(r.stiffness, s.stiffness);
      EXPECT_EQ(r.damping, s.damping);
    }
  }
  ASSERT_EQ(a.effects.size(), b.effects.size());
  for (std::size_t i = 0; i < a.effects.size(); ++i) {
    EXPECT_EQ(a.effects[i].name, b.effects[i].name);
    EXPECT_EQ(a.effects[i].joints, b.effects[i].joints);
    EXPECT_EQ(a.effects[i].params, b.effects[i].params);
    EXPECT_EQ(a.effects[i].evidence, b.effects[i].evidence);
  }
}

/// A small valid robot: cc joint, rigid link, revolute joint.
json base_robot() {
  return json::parse(R"({
    "format": "softrne-robot/1",
    "name": "test arm",
    "gravity": [0.0, 0.0, 9.81],
    "segments": [
      {"type": "cc_joint", "name": "joint1", "mass": 0.8, "height": 0.2, "diameter": 0.2,
       "chamber_distance": 0.06, "chamber_radius": 0.03, "stiffness": [40.0, 40.0], "damping": [3.0, 3.0]},
      {"type": "rigid_link", "name": "link1", "mass": 1.5, "length": 0.15,
       "com": [0.0, 0.0, 0.075], "inertia": [0.0052, 0.0052, 0.0048, 0.0, 0.0, 0.0]},
      {"type": "revolute_joint", "name": "wrist", "axis": [0.0, 0.0, 1.0], "stiffness": 0.0, "damping": 0.1}
    ]
  })");
}

std::string mutate(const std::function<void(json&)>& f) {
  json j = base_robot();
  f(j);
  return j.dump(2);
}

json& seg(json& j, int i) {
  return j["segments"][static_cast<std::size_t>(i)];
}

struct BadRobotCase {
  std::string name;
  std::string text;
  sio::Category category;
  std::vector<std::string> expect;  // substrings of the message (besides the source name)
};

std::vector<BadRobotCase> bad_robot_cases() {
  using C = sio::Category;
  const std::string base = base_robot().dump(2);
  std::string dup_key = base;
  dup_key.replace(dup_key.find("\"mass\": 0.8"), 11, "\"mass\": 0.8, \"mass\": 0.9");
  std::string overflow = base;
  overflow.replace(overflow.find("\"mass\": 1.5"), 11, "\"mass\": 1e400");
  return {
      {"syntax_trailing_comma",
       "{\"format\": \"softrne-robot/1\",\n \"segments\": [],\n}",
       C::Syntax,
       {"line 3"}},
      {"syntax_unterminated", base.substr(0, base.size() / 2), C::Syntax, {"line", "column"}},
      {"syntax_trailing_garbage", base + "\nx", C::Syntax, {"line", "column", "end of input"}},
      {"syntax_nan_literal", "{\"format\": NaN}", C::Syntax, {"line 1"}},
      {"empty_file", "  \n", C::Empty, {"empty"}},
      {"top_level_array", "[1, 2]", C::WrongType, {"top level", "object"}},
      {"missing_format", mutate([](json& j) { j.erase("format"); }), C::MissingField, {"'format'"}},
      {"unknown_format",
       mutate([](json& j) { j["format"] = "softrne-robot/2"; }),
       C::UnknownFormat,
       {"'format'", "softrne-robot/2"}},
      {"format_not_string",
       mutate([](json& j) { j["format"] = 1; }),
       C::WrongType,
       {"'format'", "string"}},
      {"report_given_as_robot",
       mutate([](json& j) { j["format"] = "softrne-loop-report/1"; }),
       C::UnknownFormat,
       {"fitted_robot"}},
      {"unknown_top_field",
       mutate([](json& j) { j["gravty"] = j["gravity"]; }),
       C::UnknownField,
       {"'gravty'", "did you mean 'gravity'"}},
      {"robot_name_not_string", mutate([](json& j) { j["name"] = 3; }), C::WrongType, {"'name'"}},
      {"missing_gravity",
       mutate([](json& j) { j.erase("gravity"); }),
       C::MissingField,
       {"'gravity'"}},
      {"gravity_two_numbers",
       mutate([](json& j) {
         j["gravity"] = {0.0, 9.81};
       }),
       C::BadShape,
       {"'gravity'", "expected 3 numbers, got 2"}},
      {"gravity_string_element",
       mutate([](json& j) { j["gravity"][2] = "9.81"; }),
       C::WrongType,
       {"'gravity'", "element 2"}},
      {"missing_segments",
       mutate([](json& j) { j.erase("segments"); }),
       C::MissingField,
       {"'segments'"}},
      {"zero_segments",
       mutate([](json& j) { j["segments"] = json::array(); }),
       C::Empty,
       {"'segments'"}},
      {"segments_not_array",
       mutate([](json& j) { j["segments"] = json::object(); }),
       C::WrongType,
       {"'segments'"}},
      {"segment_not_object", mutate([](json& j) { seg(j, 1) = 5; }), C::WrongType, {"segments[1]"}},
      {"segment_missing_type",
       mutate([](json& j) { seg(j, 0).erase("type"); }),
       C::MissingField,
       {"segments[0]", "'type'"}},
      {"unknown_segment_type",
       mutate([](json& j) { seg(j, 0)["type"] = "cc_jiont"; }),
       C::UnknownType,
       {"segments[0]", "cc_jiont", "did you mean 'cc_joint'"}},
      {"cc_negative_mass",
       mutate([](json& j) { seg(j, 0)["mass"] = -1; }),
       C::OutOfRange,
       {"segments[0] 'joint1': field 'mass': must be > 0 (got -1)"}},
      {"cc_mass_string",
       mutate([](json& j) { seg(j, 0)["mass"] = "0.8"; }),
       C::WrongType,
       {"segments[0] 'joint1'", "'mass'", "expected a number, got string"}},
      {"cc_mass_null",
       mutate([](json& j) { seg(j, 0)["mass"] = nullptr; }),
       C::WrongType,
       {"'mass'", "null"}},
      {"cc_missing_height",
       mutate([](json& j) { seg(j, 0).erase("height"); }),
       C::MissingField,
       {"'joint1'", "'height'"}},
      {"cc_zero_height",
       mutate([](json& j) { seg(j, 0)["height"] = 0.0; }),
       C::OutOfRange,
       {"'height'"}},
      {"cc_zero_diameter",
       mutate([](json& j) { seg(j, 0)["diameter"] = 0; }),
       C::OutOfRange,
       {"'diameter'"}},
      {"cc_negative_chamber_distance",
       mutate([](json& j) { seg(j, 0)["chamber_distance"] = -0.06; }),
       C::OutOfRange,
       {"'chamber_distance'"}},
      {"cc_zero_chamber_radius",
       mutate([](json& j) { seg(j, 0)["chamber_radius"] = 0; }),
       C::OutOfRange,
       {"'chamber_radius'"}},
      {"cc_stiffness_three",
       mutate([](json& j) {
         seg(j, 0)["stiffness"] = {1, 2, 3};
       }),
       C::BadShape,
       {"'stiffness'", "expected 2 numbers, got 3"}},
      {"cc_stiffness_scalar",
       mutate([](json& j) { seg(j, 0)["stiffness"] = 40.0; }),
       C::WrongType,
       {"'stiffness'", "array"}},
      {"cc_negative_damping",
       mutate([](json& j) { seg(j, 0)["damping"][1] = -3.0; }),
       C::OutOfRange,
       {"'damping[1]'", "got -3"}},
      {"cc_typo_field",
       mutate([](json& j) { seg(j, 0)["masss"] = 1.0; }),
       C::UnknownField,
       {"'joint1'", "'masss'", "did you mean 'mass'"}},
      {"cc_map_three_rows",
       mutate([](json& j) {
         seg(j, 0)["pressure_to_torque"] = {{1, 2}, {3, 4}, {5, 6}};
       }),
       C::BadShape,
       {"'pressure_to_torque'"}},
      {"cc_map_flat",
       mutate([](json& j) {
         seg(j, 0)["pressure_to_torque"] = {1, 2};
       }),
       C::BadShape,
       {"'pressure_to_torque'"}},
      {"cc_map_unequal_rows",
       mutate([](json& j) {
         seg(j, 0)["pressure_to_torque"] = {{1, 2, 3}, {3, 4}};
       }),
       C::BadShape,
       {"'pressure_to_torque'", "3 and 2"}},
      {"cc_map_empty_rows",
       mutate([](json& j) {
         seg(j, 0)["pressure_to_torque"] = {json::array(), json::array()};
       }),
       C::BadShape,
       {"'pressure_to_torque'", "K >= 1"}},
      {"cc_map_not_number",
       mutate([](json& j) {
         seg(j, 0)["pressure_to_torque"] = {{1, "x"}, {3, 4}};
       }),
       C::WrongType,
       {"'pressure_to_torque[0][1]'"}},
      {"cc_bad_inertia_model",
       mutate([](json& j) { seg(j, 0)["inertia_model"] = "exact"; }),
       C::InvalidValue,
       {"'inertia_model'", "exact"}},
      {"cc_quadrature_not_integer",
       mutate([](json& j) { seg(j, 0)["quadrature_points"] = 2.5; }),
       C::WrongType,
       {"'quadrature_points'", "integer"}},
      {"cc_quadrature_negative",
       mutate([](json& j) { seg(j, 0)["quadrature_points"] = -1; }),
       C::OutOfRange,
       {"'quadrature_points'"}},
      {"link_zero_mass",
       mutate([](json& j) { seg(j, 1)["mass"] = 0; }),
       C::OutOfRange,
       {"segments[1] 'link1': field 'mass'"}},
      {"link_negative_length",
       mutate([](json& j) { seg(j, 1)["length"] = -0.1; }),
       C::OutOfRange,
       {"'length'"}},
      {"link_com_two",
       mutate([](json& j) {
         seg(j, 1)["com"] = {0, 0};
       }),
       C::BadShape,
       {"'com'"}},
      {"link_inertia_five",
       mutate([](json& j) {
         seg(j, 1)["inertia"] = {1, 1, 1, 0, 0};
       }),
       C::BadShape,
       {"'inertia'", "expected 6 numbers, got 5"}},
      {"link_inertia_not_pd",
       mutate([](json& j) { seg(j, 1)["inertia"] = {0.005, 0.005, -0.004, 0, 0, 0}; }),
       C::InvalidValue,
       {"'inertia'", "positive definite"}},
      {"link_inertia_products_not_pd",
       mutate([](json& j) { seg(j, 1)["inertia"] = {1, 1, 1, 2, 0, 0}; }),
       C::InvalidValue,
       {"'inertia'", "positive definite"}},
      {"link_inertia_triangle",
       mutate([](json& j) { seg(j, 1)["inertia"] = {1, 1, 3, 0, 0, 0}; }),
       C::InvalidValue,
       {"'inertia'", "triangle"}},
      {"link_missing_inertia",
       mutate([](json& j) { seg(j, 1).erase("inertia"); }),
       C::MissingField,
       {"'link1'", "'inertia'"}},
      {"revolute_axis_not_unit",
       mutate([](json& j) {
         seg(j, 2)["axis"] = {0, 0.1, 1};
       }),
       C::InvalidValue,
       {"segments[2] 'wrist': field 'axis'", "unit"}},
      {"revolute_axis_zero",
       mutate([](json& j) {
         seg(j, 2)["axis"] = {0, 0, 0};
       }),
       C::InvalidValue,
       {"'axis'"}},
      {"revolute_negative_stiffness",
       mutate([](json& j) { seg(j, 2)["stiffness"] = -1; }),
       C::OutOfRange,
       {"'wrist'", "'stiffness'"}},
      {"revolute_damping_bool",
       mutate([](json& j) { seg(j, 2)["damping"] = true; }),
       C::WrongType,
       {"'damping'", "boolean"}},
      {"revolute_stiffness_array",
       mutate([](json& j) {
         seg(j, 2)["stiffness"] = {1.0, 1.0};
       }),
       C::WrongType,
       {"'stiffness'"}},
      {"duplicate_segment_name",
       mutate([](json& j) { seg(j, 2)["name"] = "joint1"; }),
       C::DuplicateName,
       {"segments[2] 'joint1'", "segments[0]"}},
      {"segment_name_not_string",
       mutate([](json& j) { seg(j, 1)["name"] = 7; }),
       C::WrongType,
       {"segments[1]", "'name'"}},
      {"segment_name_empty",
       mutate([](json& j) { seg(j, 1)["name"] = ""; }),
       C::InvalidValue,
       {"'name'", "empty"}},
      {"segment_name_comma",
       mutate([](json& j) { seg(j, 2)["name"] = "a,b"; }),
       C::InvalidValue,
       {"'name'", "comma"}},
      {"duplicate_json_key", dup_key, C::DuplicateField, {"segments[0]", "'mass'"}},
      {"number_overflow", overflow, C::NonFinite, {"segments[1].mass", "overflow"}},
      {"effects_not_array",
       mutate([](json& j) { j["effects"] = "none"; }),
       C::WrongType,
       {"'effects'"}},
      {"effect_missing_name",
       mutate([](json& j) {
         j["effects"] = {{{"joints", {"joint1"}}}};
       }),
       C::MissingField,
       {"effects[0]", "'name'"}},
      {"effect_unknown_joint",
       mutate([](json& j) {
         j["effects"] = {{{"name", "stiffening"}, {"joints", {"joint1", "nosuch"}}}};
       }),
       C::UnknownName,
       {"effects[0] 'stiffening'", "joints[1]", "nosuch"}},
      {"effect_joints_not_array",
       mutate([](json& j) {
         j["effects"] = {{{"name", "stiffening"}, {"joints", "joint1"}}};
       }),
       C::WrongType,
       {"'joints'"}},
      {"effect_param_not_number",
       mutate([](json& j) {
         j["effects"] = {{{"name", "lag"}, {"params", {{"tau", "fast"}}}}};
       }),
       C::WrongType,
       {"effects[0] 'lag'", "params.tau"}},
      {"effect_unknown_field",
       mutate([](json& j) {
         j["effects"] = {{{"name", "lag"}, {"selection_gain", 0.4}}};
       }),
       C::UnknownField,
       {"'selection_gain'"}},
  };
}

}  // namespace

TEST(IoRobotJson, ReadsArmA) {
  const sio::RobotSpec r = sio::read_robot_json(kArmA);
  EXPECT_EQ(r.name, "arm A: hanging, three CC joints");
  EXPECT_EQ(r.source, kArmA);
  EXPECT_EQ(r.gravity, Eigen::Vector3d(0.0, 0.0, 9.81));
  ASSERT_EQ(r.segments.size(), 6u);
  EXPECT_EQ(sio::num_cc_joints(r), 3u);
  EXPECT_EQ(sio::num_pressure_columns(r), 12u);
  EXPECT_EQ(sio::coordinate_names(r),
            (std::vector<std::string>{"u1", "v1", "u2", "v2", "u3", "v3"}));
  EXPECT_EQ(sio::pressure_column_names(r).front(), "p1_0");
  EXPECT_EQ(sio::pressure_column_names(r).back(), "p3_3");

  const auto& j1 = std::get<sio::CCJointSpec>(r.segments[0]);
  EXPECT_EQ(j1.name, "joint1");
  EXPECT_EQ(j1.mass, 0.8);
  EXPECT_EQ(j1.height, 0.2);
  EXPECT_EQ(j1.diameter, 0.2);
  EXPECT_EQ(j1.chamber_distance, 0.06);
  EXPECT_EQ(j1.chamber_radius, 0.03);
  EXPECT_EQ(j1.stiffness, Eigen::Vector2d(23.370848109491327, 37.11682021036924));
  EXPECT_EQ(j1.damping, Eigen::Vector2d(2.5033054010527693, 2.462695838244726));
  EXPECT_FALSE(j1.custom_pressure_map);
  EXPECT_EQ(j1.inertia_model, "lumped");
  EXPECT_EQ(j1.quadrature_points, 0);
  EXPECT_EQ(j1.pressure_to_torque, sio::default_pressure_to_torque(0.06, 0.03));

  const auto& l1 = std::get<sio::RigidLinkSpec>(r.segments[1]);
  EXPECT_EQ(l1.name, "link1");
  EXPECT_EQ(l1.mass, 1.5);
  EXPECT_EQ(l1.length, 0.15);
  EXPECT_EQ(l1.com, Eigen::Vector3d(0, 0, 0.075));
  EXPECT_EQ(l1.inertia,
            sio::inertia_from_array(0.005212499999999999, 0.005212499999999999, 0.0048, 0, 0, 0));

  const auto& j3 = std::get<sio::CCJointSpec>(r.segments[4]);
  EXPECT_EQ(j3.name, "joint3");
  EXPECT_EQ(j3.stiffness[1], 18.960748058692293);
  const auto& l3 = std::get<sio::RigidLinkSpec>(r.segments[5]);
  EXPECT_EQ(l3.mass, 0.4);
  EXPECT_EQ(l3.inertia(2, 2), 0.0005000000000000001);
  EXPECT_TRUE(r.effects.empty());
}

TEST(IoRobotJson, WriteReadRoundTripIsExact) {
  const sio::RobotSpec a = sio::read_robot_json(kArmA);
  const std::string path = temp_path("arm_a_roundtrip.json");
  sio::write_robot_json(a, path);
  const sio::RobotSpec b = sio::read_robot_json(path);
  expect_same(a, b);
  EXPECT_EQ(b.source, path);
  // The JSON values (numbers bit for bit) equal the original file's.
  EXPECT_EQ(sio::to_json(b), json::parse(slurp(kArmA)));
  // Writing again gives the same bytes; keys stay in the documented order.
  const std::string text = slurp(path);
  sio::write_robot_json(b, path);
  EXPECT_EQ(slurp(path), text);
  EXPECT_LT(text.find("\"format\""), text.find("\"gravity\""));
  EXPECT_LT(text.find("\"gravity\""), text.find("\"segments\""));
  std::filesystem::remove(path);
}

TEST(IoRobotJson, RoundTripOfAwkwardNumbersAndOptionalFields) {
  sio::RobotSpec a = sio::parse_robot_json(base_robot().dump(), "mem.json");
  auto& j1 = std::get<sio::CCJointSpec>(a.segments[0]);
  j1.stiffness = Eigen::Vector2d(0.1 + 0.2, 1.0 / 3.0);
  j1.damping = Eigen::Vector2d(5e-324, 1.7976931348623157e308);
  j1.inertia_model = "distributed";
  j1.quadrature_points = 7;
  auto& w = std::get<sio::RevoluteJointSpec>(a.segments[2]);
  w.axis = Eigen::Vector3d(1.0, 2.0, 3.0).normalized();
  a.effects.push_back(
      {"stiffening", {"joint1"}, {{"k3", 12.5}, {"k5", -1.0 / 7.0}}, "residual grows like u^3"});
  a.effects.push_back({"payload", {}, {{"mass", 0.05}}, ""});
  const std::string path = temp_path("awkward.json");
  sio::write_robot_json(a, path);
  const sio::RobotSpec b = sio::read_robot_json(path);
  expect_same(a, b);
  std::filesystem::remove(path);
}

TEST(IoRobotJson, DefaultNamesAndOptionalRobotName) {
  const std::string text = mutate([](json& j) {
    j.erase("name");
    seg(j, 1).erase("name");
    seg(j, 2).erase("name");
  });
  const sio::RobotSpec r = sio::parse_robot_json(text, "mem.json");
  EXPECT_EQ(r.name, "");
  EXPECT_EQ(sio::segment_name(r.segments[1]), "rigid_link1");
  EXPECT_EQ(sio::segment_name(r.segments[2]), "revolute_joint2");
  EXPECT_EQ(sio::coordinate_names(r), (std::vector<std::string>{"u1", "v1", "qrevolute_joint2"}));
}

TEST(IoRobotJson, IntegerNumbersAndNearlyUnitAxisAccepted) {
  const std::string text = mutate([](json& j) {
    seg(j, 0)["mass"] = 1;
    seg(j, 2)["axis"] = {0.0, 0.0, 1.0 + 5e-7};
  });
  const sio::RobotSpec r = sio::parse_robot_json(text, "mem.json");
  EXPECT_EQ(std::get<sio::CCJointSpec>(r.segments[0]).mass, 1.0);
  EXPECT_EQ(std::get<sio::RevoluteJointSpec>(r.segments[2]).axis[2],
            1.0 + 5e-7);  // not normalized silently
}

TEST(IoRobotJson, DefaultPressureMapIsEq24) {
  const sio::RobotSpec r = sio::parse_robot_json(base_robot().dump(), "mem.json");
  const auto& P = std::get<sio::CCJointSpec>(r.segments[0]).pressure_to_torque;
  const double dA = 0.06 * 3.14159265358979323846 * 0.03 * 0.03;
  ASSERT_EQ(P.cols(), 4);
  Eigen::Matrix<double, 2, 4> expected;
  expected << dA, -dA, 0, 0, 0, 0, dA, -dA;
  EXPECT_TRUE(P.isApprox(expected, 1e-15));
  // Not written back: the file keeps only what the user gave.
  EXPECT_FALSE(sio::to_json(r)["segments"][0].contains("pressure_to_torque"));
}

TEST(IoRobotJson, CustomThreeChamberMapRoundTrip) {
  // Three chambers at 0, 120, 240 degrees: tau = d A [cos, sin] per chamber (rows u, v).
  const double dA = 0.05 * 3.14159265358979323846 * 0.02 * 0.02;
  std::vector<double> ru, rv;
  for (int k = 0; k < 3; ++k) {
    const double phi = 2.0 * 3.14159265358979323846 * k / 3.0;
    ru.push_back(dA * std::sin(phi));
    rv.push_back(-dA * std::cos(phi));
  }
  const std::string text = mutate([&](json& j) { seg(j, 0)["pressure_to_torque"] = {ru, rv}; });
  const sio::RobotSpec a = sio::parse_robot_json(text, "mem.json");
  const auto& c = std::get<sio::CCJointSpec>(a.segments[0]);
  EXPECT_TRUE(c.custom_pressure_map);
  ASSERT_EQ(c.pressure_to_torque.cols(), 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(c.pressure_to_torque(0, k), ru[static_cast<std::size_t>(k)]);
    EXPECT_EQ(c.pressure_to_torque(1, k), rv[static_cast<std::size_t>(k)]);
  }
  EXPECT_EQ(sio::num_pressure_columns(a), 3u);
  EXPECT_EQ(sio::pressure_column_names(a), (std::vector<std::string>{"p1_0", "p1_1", "p1_2"}));

  const std::string path = temp_path("three_chamber.json");
  sio::write_robot_json(a, path);
  const sio::RobotSpec b = sio::read_robot_json(path);
  expect_same(a, b);
  std::filesystem::remove(path);
}

TEST(IoRobotJson, MalformedInputsTable) {
  const auto cases = bad_robot_cases();
  EXPECT_GE(cases.size(), 40u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    try {
      (void)sio::parse_robot_json(c.text, "bad_" + c.name + ".json");
      ADD_FAILURE() << c.name << ": no error";
    } catch (const sio::InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(e.category(), c.category)
          << c.name << ": got " << sio::to_string(e.category()) << ": " << msg;
      EXPECT_EQ(msg.rfind("bad_" + c.name + ".json: ", 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      for (const auto& s : c.expect)
        EXPECT_NE(msg.find(s), std::string::npos) << "'" << s << "' not in: " << msg;
    } catch (const std::exception& e) {
      ADD_FAILURE() << c.name << ": wrong exception type: " << e.what();
    }
  }
}

TEST(IoRobotJson, MissingFile) {
  try {
    (void)sio::read_robot_json("/nonexistent/robot.json");
    FAIL();
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::FileNotFound);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/robot.json"), std::string::npos);
  }
}

TEST(IoRobotJson, WriteRefusesInvalidRobot) {
  sio::RobotSpec r = sio::read_robot_json(kArmA);
  std::get<sio::CCJointSpec>(r.segments[2]).stiffness[0] = -1.0;
  const std::string path = temp_path("invalid.json");
  try {
    sio::write_robot_json(r, path);
    FAIL();
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::OutOfRange);
    EXPECT_NE(std::string(e.what()).find("segments[2] 'joint2': field 'stiffness[0]'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(IoRobotJson, NestedRobotWithPrefix) {
  json report = {{"format", "softrne-loop-report/1"}, {"fitted_robot", base_robot()}};
  report["fitted_robot"]["segments"][0]["mass"] = -2.0;
  try {
    (void)sio::robot_from_json(report["fitted_robot"], "report.json", "fitted_robot.");
    FAIL();
  } catch (const sio::InputError& e) {
    EXPECT_STREQ(
        e.what(),
        "report.json: fitted_robot.segments[0] 'joint1': field 'mass': must be > 0 (got -2)");
  }
}

TEST(IoRobotJson, CorruptedFilesGiveInputErrorOnly) {
  // Fixed-seed random byte edits of a valid file: the reader either accepts the
  // result or throws InputError with a one-line message; nothing else escapes.
  const std::string original = slurp(kArmA);
  std::mt19937 rng(12345);
  const std::string alphabet = "{}[]\",:.-+eE0123456789 \n\tabcnulltruefalse\\\x01\xff";
  int accepted = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    std::string text = original;
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const std::size_t pos = rng() % text.size();
      switch (rng() % 3) {
        case 0:
          text[pos] = alphabet[rng() % alphabet.size()];
          break;
        case 1:
          text.erase(pos, 1 + rng() % 8);
          break;
        default:
          text.insert(pos, 1, alphabet[rng() % alphabet.size()]);
          break;
      }
    }
    try {
      (void)sio::parse_robot_json(text, "fuzz.json");
      ++accepted;
    } catch (const sio::InputError& e) {
      ASSERT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      ASSERT_EQ(std::string(e.what()).rfind("fuzz.json: ", 0), 0u) << e.what();
    } catch (const std::exception& e) {
      FAIL() << "iteration " << iter << ": not an InputError: " << e.what();
    }
  }
  EXPECT_GT(accepted, 0);  // some edits keep the file valid (e.g. a digit changed)
}
