#pragma once
// Private to the avatar importer: mapping a rig's joint names onto the
// canonical skeleton (joint_naming.cc).

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "sim/body/avatar_import.h"

namespace irbench::import_internal {

// The first `limit` names joined with ", ", then the total when there are more.
std::string JoinNames(const std::vector<std::string>& names, size_t limit = 60);

// MapRigJoints with `file` named in its errors: the built-in table mapping the
// most joints, then the caller's overrides.
JointMapping MapJoints(const std::vector<std::string>& rig_names,
                       const std::map<std::string, std::string>& overrides,
                       const std::string& file);

}  // namespace irbench::import_internal
