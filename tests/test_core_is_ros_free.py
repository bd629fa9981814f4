"""The core (everything outside econet_ros/nodes) must work on machines without ROS: importing
it, and running its command line, never loads rclpy or any ROS message package."""
import pkgutil
import subprocess
import sys

import econet_ros

CORE = sorted(m.name for m in pkgutil.iter_modules(econet_ros.__path__)
              if m.name not in ("nodes", "__main__"))


def test_core_modules_load_no_ros():
    assert {"world", "controllers", "evolution", "engine", "analysis", "bags"} <= set(CORE)
    code = ("import sys\n"
            + "".join(f"import econet_ros.{name}\n" for name in CORE)
            + "ros = sorted(m for m in sys.modules if m.split('.')[0] in "
              "('rclpy', 'econet_msgs', 'sensor_msgs', 'std_msgs', 'visualization_msgs'))\n"
            + "print(','.join(ros))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "", f"ROS modules loaded by the core: {result.stdout}"
