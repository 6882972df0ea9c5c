# shellcheck shell=bash
# Source me (bash):  source scripts/env.sh
# Activates the project venv (.venv, made by scripts/setup) and sets everything a ROS 2 process
# of this project needs. Safe to source more than once and under `set -euo pipefail`.
# It does not set ROS_DOMAIN_ID: tests allocate their own (collide_ros/ros_domain.py),
# scripts/demo picks a free one when you have not exported one yourself.

_lc_env_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
LIBCOLLIDE_ROOT="$(cd "${_lc_env_dir}/.." && pwd)"
export LIBCOLLIDE_ROOT
export LIBCOLLIDE_VENV="${LIBCOLLIDE_ROOT}/.venv"
# Where scripts/setup builds the C library (libcollide.so lands directly in it).
export LIBCOLLIDE_BUILD_DIR="${LIBCOLLIDE_ROOT}/build"

# prepend VAR DIR: put DIR first in the colon list VAR, without duplicates.
_lc_prepend() {
  local var="$1" dir="$2" cur
  cur="${!var:-}"
  cur=":${cur}:"
  cur="${cur//:${dir}:/:}"
  cur="${cur#:}"
  cur="${cur%:}"
  if [ -n "${cur}" ]; then
    printf -v "${var}" '%s:%s' "${dir}" "${cur}"
  else
    printf -v "${var}" '%s' "${dir}"
  fi
  export "${var?}"
}

# ROS discovery stays on this machine (Jazzy's default SUBNET multicasts on every interface).
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
# The deprecated ROS_LOCALHOST_ONLY would override the range above with a warning.
unset ROS_LOCALHOST_ONLY
export RMW_IMPLEMENTATION="${RMW_IMPLEMENTATION:-rmw_fastrtps_cpp}"

# Python packages of the project (collide, collide_ros).
_lc_prepend PYTHONPATH "${LIBCOLLIDE_ROOT}/ros_pkg"
_lc_prepend LD_LIBRARY_PATH "${LIBCOLLIDE_BUILD_DIR}"

if [ -x "${LIBCOLLIDE_VENV}/bin/python" ]; then
  # Activate (what bin/activate does, minus the prompt).
  export VIRTUAL_ENV="${LIBCOLLIDE_VENV}"
  _lc_prepend PATH "${LIBCOLLIDE_VENV}/bin"
  unset PYTHONHOME
  # The ROS wheels' libraries: <venv>/lib and site-packages/ros_*.libs. The wheels' .pth hook
  # (ros_wheels_bootstrapper) would otherwise re-exec every python process to add these.
  _lc_site="$(echo "${LIBCOLLIDE_VENV}"/lib/python3*/site-packages)"
  for _lc_d in "${_lc_site}"/ros_*.libs; do
    if [ -d "${_lc_d}" ]; then _lc_prepend LD_LIBRARY_PATH "${_lc_d}"; fi
  done
  _lc_prepend LD_LIBRARY_PATH "${LIBCOLLIDE_VENV}/lib"
  export _ROS_WHEELS_BOOTSTRAP_COMPLETE=1
  # ament index: where rclpy/rosidl find packages, incl. libcollide_msgs and tf2_msgs.
  _lc_prepend AMENT_PREFIX_PATH "${LIBCOLLIDE_VENV}"
  unset _lc_site _lc_d
else
  echo "scripts/env.sh: ${LIBCOLLIDE_VENV} does not exist yet; run scripts/setup" >&2
fi
hash -r 2>/dev/null || true
unset _lc_env_dir
