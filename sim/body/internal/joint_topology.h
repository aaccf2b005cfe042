#pragma once
// Private to the avatar importer: the canonical joints of a rig whose names no
// table knows, found from its hierarchy and bind pose (joint_topology.cc).

#include <string>

#include "sim/body/avatar_import.h"
#include "sim/body/internal/imported_rig.h"

namespace irbench::import_internal {

// Maps the rig's joints by shape: joints that carry no skin weight below them
// (IK targets, pole helpers, end markers) are set aside; the pelvis is the
// first joint, down from the root, where three weighted chains branch (the
// spine holds the most joints, the legs are the next two); the chest is the
// first joint up the spine where three chains branch (the one reaching
// highest is the neck and head, the two others the arms); an arm is clavicle
// (when its first bone is short), shoulder, elbow (the joint nearest the
// middle of shoulder to hand) and wrist (where the fingers branch, or the
// chain's end); a leg is hip, knee and ankle (where the bone turns level
// towards the toes or shortens to a foot). Which side is left is settled later by the feet
// (PlaceRig). Convention "hierarchy". Throws InputError(file, "skin") naming
// the first chain missing ("no arm chain: ...", "no leg chain: ...", "no
// torso chain: ...").
JointMapping MapJointsByHierarchy(const Rig& rig, const std::string& file);

}  // namespace irbench::import_internal
