#pragma once
/// \file
/// \brief Read and write `robot.json` (format `softrne-robot/1`,
/// docs/formats.md section 1), with strict validation: every problem is
/// an InputError with a one-line message naming the file, the segment and the field.
/// The schema is here; the strict JSON reading it uses is strict_json.hpp's.

#include <algorithm>
#include <cstddef>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "softrne/io/errors.hpp"
#include "softrne/io/robot_spec.hpp"
#include "softrne/io/robot_validate.hpp"
#include "softrne/io/strict_json.hpp"

namespace softrne::io {

/// \brief The format string this reader and writer know.
inline constexpr const char* kRobotFormat = "softrne-robot/1";

namespace detail {

/// \brief Ends the message of a document nested deeper than kMaxJsonDepth: a robot
/// description needs 5 levels (top level, segments, segment, pressure_to_torque, row).
inline constexpr const char* kRobotJsonDepthNote = " (a robot description needs 5)";

inline CCJointSpec read_cc_joint(const ObjectReader& r, const std::string& source) {
  r.only({"type", "name", "mass", "height", "diameter", "chamber_distance", "chamber_radius",
          "stiffness", "damping", "pressure_to_torque", "inertia_model", "quadrature_points"});
  CCJointSpec j;
  j.mass = r.number("mass");
  j.height = r.number("height");
  j.diameter = r.number("diameter");
  j.chamber_distance = r.number("chamber_distance");
  j.chamber_radius = r.number("chamber_radius");
  j.stiffness = r.fixed<2>("stiffness");
  j.damping = r.fixed<2>("damping");
  if (r.has("pressure_to_torque")) {
    const auto& v = r.at("pressure_to_torque");
    const std::string w = r.fw("pressure_to_torque");
    if (!v.is_array() || v.size() != 2 || !v[0].is_array() || !v[1].is_array())
      throw InputError(v.is_array() ? Category::BadShape : Category::WrongType, source, w,
                       "expected 2 rows (u, v) of K numbers, [[...], [...]], got " + describe(v));
    const std::size_t K = v[0].size();
    if (K < 1 || v[1].size() != K)
      throw InputError(Category::BadShape, source, w,
                       "rows must have the same length K >= 1 (got " + std::to_string(v[0].size()) +
                           " and " + std::to_string(v[1].size()) + ")");
    j.pressure_to_torque.resize(2, static_cast<Eigen::Index>(K));
    for (std::size_t row = 0; row < 2; ++row)
      for (std::size_t k = 0; k < K; ++k)
        j.pressure_to_torque(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(k)) =
            r.as_number(v[row][k], r.fw("pressure_to_torque[" + std::to_string(row) + "][" +
                                        std::to_string(k) + "]"));
    j.custom_pressure_map = true;
  } else {
    j.pressure_to_torque = default_pressure_to_torque(j.chamber_distance, j.chamber_radius);
  }
  j.inertia_model = r.optional_string("inertia_model", "lumped");
  if (r.has("quadrature_points")) j.quadrature_points = r.integer("quadrature_points");
  return j;
}

inline RigidLinkSpec read_rigid_link(const ObjectReader& r) {
  r.only({"type", "name", "mass", "length", "com", "inertia"});
  RigidLinkSpec l;
  l.mass = r.number("mass");
  l.length = r.number("length");
  l.com = r.fixed<3>("com");
  const auto a = r.fixed<6>("inertia");
  l.inertia = inertia_from_array(a[0], a[1], a[2], a[3], a[4], a[5]);
  return l;
}

inline RevoluteJointSpec read_revolute_joint(const ObjectReader& r) {
  r.only({"type", "name", "axis", "stiffness", "damping"});
  RevoluteJointSpec j;
  j.axis = r.fixed<3>("axis");
  j.stiffness = r.number("stiffness");
  j.damping = r.number("damping");
  return j;
}

inline SegmentSpec read_segment(const nlohmann::json& v, std::size_t index,
                                const std::string& source, const std::string& prefix) {
  const std::string where0 = segment_where(prefix, index, "");
  require_object(v, source, where0);
  ObjectReader r(v, source, where0);
  const std::string type = r.string("type");
  static const std::vector<std::string> kTypes = {"cc_joint", "rigid_link", "revolute_joint"};
  if (std::find(kTypes.begin(), kTypes.end(), type) == kTypes.end())
    throw InputError(Category::UnknownType, source, r.fw("type"),
                     "unknown segment type " + quoted(type) + suggest(type, kTypes));
  const std::string name = r.optional_string("name", type + std::to_string(index));
  r.set_where(segment_where(prefix, index, name));
  SegmentSpec s;
  if (type == "cc_joint") {
    CCJointSpec j = read_cc_joint(r, source);
    j.name = name;
    s = std::move(j);
  } else if (type == "rigid_link") {
    RigidLinkSpec l = read_rigid_link(r);
    l.name = name;
    s = std::move(l);
  } else {
    RevoluteJointSpec j = read_revolute_joint(r);
    j.name = name;
    s = std::move(j);
  }
  validate_segment(s, index, source, prefix);
  return s;
}

inline EffectSpec read_effect(const nlohmann::json& v, std::size_t index, const std::string& source,
                              const std::string& prefix) {
  const std::string where0 = effect_where(prefix, index, "");
  require_object(v, source, where0);
  ObjectReader r(v, source, where0);
  EffectSpec e;
  e.name = r.string("name");
  r.set_where(effect_where(prefix, index, e.name));
  r.only({"name", "joints", "params", "evidence"});
  if (r.has("joints")) e.joints = r.strings("joints");
  if (r.has("params")) {
    const auto& p = r.at("params");
    if (!p.is_object())
      throw InputError(Category::WrongType, source, r.fw("params"),
                       "expected an object of numbers, got " + describe(p));
    for (auto it = p.begin(); it != p.end(); ++it)
      e.params[it.key()] = r.as_number(it.value(), r.fw("params." + it.key()));
  }
  e.evidence = r.optional_string("evidence", "");
  return e;
}

inline MarkerSpec read_marker(const nlohmann::json& v, std::size_t index, const std::string& source,
                              const std::string& prefix) {
  const std::string where0 = marker_where(prefix, index, "");
  require_object(v, source, where0);
  ObjectReader r(v, source, where0);
  MarkerSpec m;
  m.name = r.string("name");
  r.set_where(marker_where(prefix, index, m.name));
  r.only({"name", "segment", "offset"});
  m.segment = r.string("segment");
  m.offset = r.fixed<3>("offset");
  return m;
}

template <class Json>
Json to_json_impl(const RobotSpec& robot) {
  auto vec = [](const auto& v) {
    Json a = Json::array();
    for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
    return a;
  };
  Json j = Json::object();
  j["format"] = kRobotFormat;
  j["name"] = robot.name;
  j["gravity"] = vec(robot.gravity);
  Json segs = Json::array();
  for (const auto& s : robot.segments) {
    Json o = Json::object();
    o["type"] = segment_type(s);
    o["name"] = segment_name(s);
    if (const auto* c = std::get_if<CCJointSpec>(&s)) {
      o["mass"] = c->mass;
      o["height"] = c->height;
      o["diameter"] = c->diameter;
      o["chamber_distance"] = c->chamber_distance;
      o["chamber_radius"] = c->chamber_radius;
      o["stiffness"] = vec(c->stiffness);
      o["damping"] = vec(c->damping);
      if (c->custom_pressure_map) {
        Json rows = Json::array();
        for (Eigen::Index r = 0; r < 2; ++r) rows.push_back(vec(c->pressure_to_torque.row(r)));
        o["pressure_to_torque"] = rows;
      }
      if (c->inertia_model != "lumped") o["inertia_model"] = c->inertia_model;
      if (c->quadrature_points != 0) o["quadrature_points"] = c->quadrature_points;
    } else if (const auto* l = std::get_if<RigidLinkSpec>(&s)) {
      o["mass"] = l->mass;
      o["length"] = l->length;
      o["com"] = vec(l->com);
      o["inertia"] = vec(inertia_to_array(l->inertia));
    } else if (const auto* r = std::get_if<RevoluteJointSpec>(&s)) {
      o["axis"] = vec(r->axis);
      o["stiffness"] = r->stiffness;
      o["damping"] = r->damping;
    }
    segs.push_back(std::move(o));
  }
  j["segments"] = std::move(segs);
  if (!robot.effects.empty()) {
    Json effs = Json::array();
    for (const auto& e : robot.effects) {
      Json o = Json::object();
      o["name"] = e.name;
      o["joints"] = e.joints;
      Json params = Json::object();
      for (const auto& [k, v] : e.params) params[k] = v;
      o["params"] = std::move(params);
      o["evidence"] = e.evidence;
      effs.push_back(std::move(o));
    }
    j["effects"] = std::move(effs);
  }
  if (!robot.markers.empty()) {
    Json marks = Json::array();
    for (const auto& m : robot.markers) {
      Json o = Json::object();
      o["name"] = m.name;
      o["segment"] = m.segment;
      o["offset"] = vec(m.offset);
      marks.push_back(std::move(o));
    }
    j["markers"] = std::move(marks);
  }
  return j;
}

}  // namespace detail

/// \brief Build a RobotSpec from parsed JSON (e.g. a report's `fitted_robot`).
/// \param[in] j The parsed `softrne-robot/1` object.
/// \param[in] source File name for messages.
/// \param[in] prefix Location prefix such as "fitted_robot." (a robot inside a report).
/// \return The validated robot.
/// \throws InputError naming source, the field and what is wrong (formats.md section 1).
inline RobotSpec robot_from_json(const nlohmann::json& j, const std::string& source,
                                 const std::string& prefix = "") {
  const std::string top =
      prefix.empty() ? "top level" : prefix.substr(0, prefix.size() - (prefix.back() == '.'));
  detail::require_object(j, source, top);
  detail::ObjectReader r(j, source, prefix.empty() ? "" : top);
  // The version first: a file of another format gets that error, not a list of unknown fields.
  const auto it = j.find("format");
  if (it == j.end())
    throw InputError(Category::MissingField, source, r.fw("format"),
                     std::string("missing; a robot description starts with \"format\": \"") +
                         kRobotFormat + "\"");
  const std::string format = r.string("format");
  if (format != kRobotFormat) {
    std::string hint;
    if (format.rfind("softrne-loop-report/", 0) == 0)
      hint = " (this is a loop report; its robot is the field 'fitted_robot')";
    throw InputError(
        Category::UnknownFormat, source, r.fw("format"),
        "unknown format " + detail::quoted(format) + ", expected '" + kRobotFormat + "'" + hint);
  }
  r.only({"format", "name", "gravity", "segments", "effects", "markers"});
  RobotSpec robot;
  robot.source = source;
  robot.name = r.optional_string("name", "");
  robot.gravity = r.fixed<3>("gravity");
  const auto& segs = r.at("segments");
  if (!segs.is_array())
    throw InputError(Category::WrongType, source, r.fw("segments"),
                     "expected an array of segments, got " + detail::describe(segs));
  if (segs.empty())
    throw InputError(Category::Empty, source, r.fw("segments"), "must hold at least one segment");
  for (std::size_t i = 0; i < segs.size(); ++i)
    robot.segments.push_back(detail::read_segment(segs[i], i, source, prefix));
  if (r.has("effects")) {
    const auto& effs = r.at("effects");
    if (!effs.is_array())
      throw InputError(Category::WrongType, source, r.fw("effects"),
                       "expected an array of effects, got " + detail::describe(effs));
    for (std::size_t i = 0; i < effs.size(); ++i)
      robot.effects.push_back(detail::read_effect(effs[i], i, source, prefix));
  }
  if (r.has("markers")) {
    const auto& marks = r.at("markers");
    if (!marks.is_array())
      throw InputError(Category::WrongType, source, r.fw("markers"),
                       "expected an array of markers, got " + detail::describe(marks));
    for (std::size_t i = 0; i < marks.size(); ++i)
      robot.markers.push_back(detail::read_marker(marks[i], i, source, prefix));
  }
  detail::validate_robot_global(robot, source, prefix);
  return robot;
}

/// \brief Parse the text of a `robot.json`; `source_name` names it in messages.
/// \param[in] text The file's content.
/// \param[in] source_name The file's name, for messages.
/// \return The validated robot.
/// \throws InputError (Syntax, MissingField, UnknownField, OutOfRange, ...) naming the file,
///   the field and what is wrong.
inline RobotSpec parse_robot_json(const std::string& text, const std::string& source_name) {
  return robot_from_json(
      detail::parse_json_strict(text, source_name, detail::kRobotJsonDepthNote), source_name);
}

/// \brief Read and validate a `robot.json` file.
/// \param[in] path The file.
/// \return The validated robot (build a chain of it with softrne::build_arm).
/// \throws InputError (FileNotFound, ReadFailed, or as parse_robot_json()).
inline RobotSpec read_robot_json(const std::string& path) {
  return parse_robot_json(detail::read_text_file(path), path);
}

/// \brief The `softrne-robot/1` JSON of a robot (keys sorted, as nlohmann::json does).
/// \param[in] robot A robot.
/// \return Its JSON.
inline nlohmann::json to_json(const RobotSpec& robot) {
  return detail::to_json_impl<nlohmann::json>(robot);
}

/// \brief The `softrne-robot/1` JSON of a robot with keys in the documented order.
/// \param[in] robot A robot.
/// \return Its JSON, keys in the order of formats.md.
inline nlohmann::ordered_json to_ordered_json(const RobotSpec& robot) {
  return detail::to_json_impl<nlohmann::ordered_json>(robot);
}

/// \brief Validate `robot` and write it as `softrne-robot/1` (2-space indent, keys
/// in the documented order, doubles in shortest round-trip form: reading the file
/// back gives bit-identical numbers). Throws InputError (WriteFailed, or the
/// validation error, with source "<path> (writing)").
/// \param[in] robot The robot.
/// \param[in] path The output file.
/// \throws InputError if robot breaks a rule or the file cannot be written.
inline void write_robot_json(const RobotSpec& robot, const std::string& path) {
  const std::string src = path + " (writing)";
  for (std::size_t i = 0; i < robot.segments.size(); ++i)
    detail::validate_segment(robot.segments[i], i, src);
  detail::validate_robot_global(robot, src);
  detail::write_text_file(path, to_ordered_json(robot).dump(2) + "\n");
}

}  // namespace softrne::io
