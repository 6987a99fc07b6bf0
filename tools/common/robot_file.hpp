#pragma once
/// \file
/// \brief The arm of a robot file for the command-line tools: one rule for a file that reads
/// but does not build (README "Exit codes").

#include <stdexcept>
#include <string>

#include "softrne/arm/arm_description.hpp"
#include "softrne/io/errors.hpp"
#include "softrne/io/robot_json.hpp"

namespace softrne::cli {

/// \brief build_arm(spec) for the robot file `path`. A file that reads but does not build (an
/// effect's parameters or joints) is a problem with an input file like any other: an
/// io::InputError naming the file once (exit status 3 in every tool), not a run failure.
/// \param[in] spec The file's contents (io::read_robot_json(path)).
/// \param[in] path The file as the user named it.
/// \return The arm.
/// \throws io::InputError if build_arm rejects the file.
inline ArmDescription build_robot(const io::RobotSpec& spec, const std::string& path) {
  try {
    return build_arm(spec);
  } catch (const std::invalid_argument& e) {
    // build_arm names the file itself where the spec knows it (spec.source); say it once.
    std::string detail = e.what();
    const std::string prefix = path + ": ";
    if (detail.compare(0, prefix.size(), prefix) == 0) detail.erase(0, prefix.size());
    throw io::InputError(io::Category::InvalidValue, path, "", detail);
  }
}

}  // namespace softrne::cli
