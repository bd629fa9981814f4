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

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['tests', 'tests.*']),
    data_files=data_files,
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='econet developers',
    maintainer_email='econet-dev@example.org',
    description='ROS 2 and Python reimplementation of the econet infant-reaching model.',
    license='MIT',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'econet = econet_ros.cli:main',
            'world_node = econet_ros.nodes.world_node:main',
            'controller_node = econet_ros.nodes.controller_node:main',
            'supervisor_node = econet_ros.nodes.supervisor_node:main',
            'recorder_node = econet_ros.nodes.recorder_node:main',
            'viewer_node = econet_ros.nodes.viewer_node:main',
        ],
        # Controllers by name (econet_ros.plugins.BUILTIN); other packages add their own here.
        'econet_ros.controllers': [
            'normal = econet_ros.controllers:FourLayerNetwork',
            'three-layer = econet_ros.controllers:ThreeLayerNetwork',
            'random = econet_ros.controllers:RandomMovement',
            'reacher = econet_ros.reacher:HandWrittenReacher',
        ],
    },
)
