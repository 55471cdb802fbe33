// The header trac_ik_kinematics_plugin includes (the old pluginlib name). Debian 12's pluginlib ships only the
// .hpp it has long forwarded to; this forwards to it. Build-environment shim of `make moveit`, not upstream code.
#pragma once
#include <pluginlib/class_list_macros.hpp>
