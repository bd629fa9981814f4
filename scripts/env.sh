# shellcheck shell=sh
# Source me (bash or POSIX sh):  . scripts/env.sh
# Activates .venv, runs Python from the working tree, and exposes the colcon-built econet_msgs
# (what install/local_setup.sh would do, without its dependence on the shell being detected).
# Run scripts/setup first (scripts/test and scripts/run do).

if [ -n "${BASH_SOURCE:-}" ]; then
  _econet_env_file="${BASH_SOURCE}"
elif [ -n "${ZSH_VERSION:-}" ]; then
  # shellcheck disable=SC2296
  _econet_env_file="${(%):-%x}"
else
  _econet_env_file="${ECONET_ENV_FILE:-scripts/env.sh}"   # POSIX sh cannot tell; assume cwd = repo
fi
ECONET_ROOT="$(cd "$(dirname "$_econet_env_file")/.." && pwd)"
export ECONET_ROOT
unset _econet_env_file

# --- virtual environment (like bin/activate, minus the prompt) ---
export VIRTUAL_ENV="$ECONET_ROOT/.venv"
case ":$PATH:" in
  *":$VIRTUAL_ENV/bin:"*) ;;
  *) PATH="$VIRTUAL_ENV/bin:$PATH" ;;
esac
export PATH
unset PYTHONHOME

# _econet_prepend VAR DIR: put DIR first in the colon list VAR (removing an older copy).
_econet_prepend() {
  _cur="$(eval "printf '%s' \"\${$1:-}\"")"
  _new="$2"
  _old_ifs="$IFS"; IFS=:
  for _p in $_cur; do
    if [ -n "$_p" ] && [ "$_p" != "$2" ]; then _new="$_new:$_p"; fi
  done
  IFS="$_old_ifs"
  eval "export $1=\"\$_new\""
  unset _cur _new _old_ifs _p
}

# Order matters: each prepend goes in front of the previous ones.
_econet_pyver="$("$VIRTUAL_ENV/bin/python" -c 'import sys; print("python%d.%d" % sys.version_info[:2])' 2>/dev/null || echo python3.11)"

# --- colcon install space: econet_msgs (generated Python module + its C libraries) ---
_econet_prepend AMENT_PREFIX_PATH "$VIRTUAL_ENV"
_econet_prepend AMENT_PREFIX_PATH "$ECONET_ROOT/install/econet_ros"
_econet_prepend AMENT_PREFIX_PATH "$ECONET_ROOT/install/econet_msgs"
_econet_prepend CMAKE_PREFIX_PATH "$ECONET_ROOT/install/econet_msgs"
_econet_prepend LD_LIBRARY_PATH "$ECONET_ROOT/install/econet_msgs/lib"
_econet_prepend PYTHONPATH "$ECONET_ROOT/install/econet_msgs/lib/$_econet_pyver/site-packages"
# econet_ros' installed metadata (entry points for install/econet_ros/lib/econet_ros/econet);
# its copy of the sources there is shadowed by the working tree, which comes first:
_econet_prepend PYTHONPATH "$ECONET_ROOT/install/econet_ros/lib/$_econet_pyver/site-packages"
# --- the working tree comes first, so `python -m econet_ros` runs the current sources ---
_econet_prepend PYTHONPATH "$ECONET_ROOT"
unset _econet_pyver
unset -f _econet_prepend
