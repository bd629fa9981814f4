#!/usr/bin/env python3
"""Rewrite the wheel build container's Python paths in the ROS wheels' cmake files.

The ros-* wheels from PyPI install cmake export files under $VIRTUAL_ENV/share/*/cmake/ that
hard-code the paths of the container the wheels were built in.  CMake refuses to configure an
interface package until they point at this venv's Python.  Idempotent: files already fixed are
left untouched.  Run with the venv's python (after every install of ROS wheels).
"""
import glob
import os
import sys
import sysconfig

BUILD_INCLUDE = '/opt/python/cp311-cp311/include/python3.11'
BUILD_PURELIB = '/opt/python/cp311-cp311/lib/python3.11/site-packages'


def main():
    prefix = os.environ.get('VIRTUAL_ENV') or sys.prefix
    paths = sysconfig.get_paths()
    replacements = [(BUILD_INCLUDE, paths['include']), (BUILD_PURELIB, paths['purelib'])]
    changed = 0
    for path in sorted(glob.glob(os.path.join(prefix, 'share', '*', 'cmake', '*.cmake'))):
        with open(path, encoding='utf-8') as f:
            text = f.read()
        new = text
        for old, repl in replacements:
            new = new.replace(old, repl)
        if new != text:
            with open(path, 'w', encoding='utf-8') as f:
                f.write(new)
            changed += 1
    leftover = [p for p in glob.glob(os.path.join(prefix, 'share', '*', 'cmake', '*.cmake'))
                if '/opt/python/cp311-cp311' in open(p, encoding='utf-8').read()]
    if leftover:
        print('fix_ros_cmake: unhandled build-container paths remain in:', *leftover,
              sep='\n  ', file=sys.stderr)
        return 1
    print(f'fix_ros_cmake: rewrote {changed} file(s) under {prefix}/share')
    return 0


if __name__ == '__main__':
    sys.exit(main())
