"""econet_ros: built by colcon as the root ament_python package (scripts/setup), and installable
by pip without ROS: `pip install .` gives the ROS-free core (econet evolve, study, analyze,
evaluate, compare, check); the extras add a feature each, e.g. `pip install ".[sweep,gym,bag]"`.

The ranges below hold the versions this project is tested with (requirements.txt pins them
exactly, with ROS 2; scripts/setup installs that list): from that release (or the first with
what the code uses) up to the next major one."""
import os
from glob import glob

from setuptools import find_packages, setup

package_name = 'econet_ros'

data_files = [
    ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
    ('share/' + package_name, ['package.xml']),
]
if os.path.isdir('launch'):
    data_files.append(('share/' + package_name + '/launch', glob('launch/*.py')))

# econet_msgs' message definitions travel inside the package as econet_ros/recording/msg, so
# that bags are read and written without ROS (recording/messages.py looks there).
MSG_PACKAGE = package_name + '.recording.msg'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['tests', 'tests.*']) + [MSG_PACKAGE],
    package_dir={MSG_PACKAGE: 'econet_msgs/msg'},
    package_data={MSG_PACKAGE: ['*.msg']},
    data_files=data_files,
    python_requires='>=3.11',
    install_requires=[
        'numpy>=2,<3',               # the code is written for NumPy 2; numba narrows it
        'numba>=0.68,<1',          # the compiled kernels
        'tqdm>=4.70,<5',           # progress bars of evolve, study and sweep
        'cma>=4.5,<5',             # the CMA-ES optimizer (evolution.optimizer = cmaes)
        'scipy>=1.17,<2',          # the report's t, beta and binomial quantiles
        'matplotlib>=3.11,<4',     # figures and bag pictures; brings Pillow for the GIFs
    ],
    extras_require={
        'sweep': ['ray>=2.60,<3'],                  # econet sweep (Ray tasks, local or cluster)
        'gym': ['gymnasium>=1.1,<2'],               # econet_ros/Reach-v0 and its vector env
        'bag': ['rosbags>=0.11,<1'],                # econet bag, econet evaluate --bag
        'view': ['foxglove-sdk>=0.30,<1'],          # the viewer node (needs ROS 2 as well)
        # --device cuda; econet_ros.cuda_kernels turns off FMA contraction through numba-cuda's
        # internals, so the range is the tested minor release
        'cuda': ['numba-cuda>=0.30.4,<0.31'],
    },
    zip_safe=True,
    maintainer='econet developers',
    maintainer_email='econet-dev@example.org',
    description='ROS 2 and Python reimplementation of the econet infant-reaching model.',
    license='MIT',
    tests_require=['pytest'],
    # entry points (console scripts, controllers, sweep rules and verbs): setup.cfg
)
