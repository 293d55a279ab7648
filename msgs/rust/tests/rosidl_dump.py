#!/usr/bin/python3
"""Parse every kerf_msgs interface file with the real ROS 2 IDL parser and print JSON.

Usage: /usr/bin/python3 rosidl_dump.py MSGS_DIR

MSGS_DIR is the kerf_msgs colcon package (the directory holding package.xml). The
files parsed are kerf's own MSGS_DIR/{msg,srv,action}/* and the transcribed standard
interfaces MSGS_DIR/rust/interfaces/<package>/{msg,srv,action}/*.

The parser is rosidl_adapter.parser from the rosidl package (Debian: python3-rosidl).
Besides parsing (which proves every file is valid ROS 2 IDL) this script checks that
every nested message type a file uses is itself defined in the set, and that the
packages kerf's own files use are dependencies in package.xml and CMakeLists.txt.
Any failure exits with status 1 and a message on stderr.

The JSON printed on stdout is read by msgs/rust/tests/drift.rs, which compares it with
the Rust parser's view of the same files.
"""

import json
import math
import os
import re
import sys
import xml.etree.ElementTree as ET

from rosidl_adapter.parser import (
    parse_action_file,
    parse_message_file,
    parse_service_file,
)

KINDS = ('msg', 'srv', 'action')


def fail(message):
    print('rosidl_dump: ' + message, file=sys.stderr)
    sys.exit(1)


def value_json(value):
    """JSON form of a parsed constant or default value; non-finite floats as strings."""
    if isinstance(value, list):
        return [value_json(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return 'nan' if math.isnan(value) else ('inf' if value > 0 else '-inf')
    return value


def type_json(t):
    return {
        'package': t.pkg_name,
        'type': t.type,
        'string_upper_bound': t.string_upper_bound,
        'is_array': bool(t.is_array),
        'array_size': t.array_size,
        'is_upper_bound': bool(t.is_upper_bound),
    }


def message_json(spec):
    return {
        'name': spec.msg_name,
        'fields': [
            {
                'name': f.name,
                'type': type_json(f.type),
                'default': value_json(f.default_value),
            }
            for f in spec.fields
        ],
        'constants': [
            {'name': c.name, 'type': c.type, 'value': value_json(c.value)}
            for c in spec.constants
        ],
    }


def parse(kind, package, path):
    try:
        if kind == 'msg':
            return [parse_message_file(package, path)]
        if kind == 'srv':
            spec = parse_service_file(package, path)
            return [spec.request, spec.response]
        spec = parse_action_file(package, path)
        return [spec.goal, spec.result, spec.feedback]
    except Exception as err:  # rosidl raises many exception types
        fail('%s is not valid ROS 2 IDL: %s: %s' % (path, type(err).__name__, err))


def interface_files(msgs_dir):
    """(kind, package, path relative to msgs_dir) of every interface file."""
    tree = ET.parse(os.path.join(msgs_dir, 'package.xml'))
    own_package = tree.getroot().findtext('name')
    found = []
    for kind in KINDS:
        d = os.path.join(msgs_dir, kind)
        if os.path.isdir(d):
            for name in sorted(os.listdir(d)):
                if name.endswith('.' + kind):
                    found.append((kind, own_package, os.path.join(kind, name)))
    ref = os.path.join('rust', 'interfaces')
    for package in sorted(os.listdir(os.path.join(msgs_dir, ref))):
        for kind in KINDS:
            d = os.path.join(msgs_dir, ref, package, kind)
            if os.path.isdir(d):
                for name in sorted(os.listdir(d)):
                    if name.endswith('.' + kind):
                        found.append((kind, package, os.path.join(ref, package, kind, name)))
    return own_package, found


def check_dependencies(msgs_dir, own_package, files, parsed):
    tree = ET.parse(os.path.join(msgs_dir, 'package.xml'))
    root = tree.getroot()
    depends = {e.text.strip() for tag in ('depend', 'build_depend') for e in root.iter(tag)}
    with open(os.path.join(msgs_dir, 'CMakeLists.txt'), encoding='utf-8') as h:
        cmake = h.read()
    match = re.search(r'rosidl_generate_interfaces\((.*?)\)', cmake, re.S)
    if match is None:
        fail('CMakeLists.txt has no rosidl_generate_interfaces(...) call')
    body = match.group(1)
    cmake_files = set(re.findall(r'"([^"]+)"', body))
    cmake_deps = set(body.split('DEPENDENCIES', 1)[1].split()) if 'DEPENDENCIES' in body else set()
    for (kind, package, path), parts in zip(files, parsed):
        if package != own_package:
            continue
        if path not in cmake_files:
            fail('%s is not listed in rosidl_generate_interfaces of CMakeLists.txt' % path)
        for part in parts:
            for field in part.fields:
                pkg = field.type.pkg_name
                if pkg is None or pkg == own_package:
                    continue
                if pkg not in depends:
                    fail('%s uses %s/%s but package.xml has no <depend>%s</depend>'
                         % (path, pkg, field.type.type, pkg))
                if pkg not in cmake_deps:
                    fail('%s uses %s/%s but CMakeLists.txt lists no DEPENDENCIES %s'
                         % (path, pkg, field.type.type, pkg))
    for listed in sorted(cmake_files):
        if not os.path.isfile(os.path.join(msgs_dir, listed)):
            fail('CMakeLists.txt lists %s, which does not exist' % listed)


def main():
    if len(sys.argv) != 2:
        fail('usage: rosidl_dump.py MSGS_DIR')
    msgs_dir = sys.argv[1]
    own_package, files = interface_files(msgs_dir)
    parsed = [parse(kind, package, os.path.join(msgs_dir, path)) for kind, package, path in files]

    # Every nested message type must be defined in the set (proves the transcription
    # and kerf's own files reference only known types).
    known = {(package, os.path.splitext(os.path.basename(path))[0])
             for (kind, package, path) in files if kind == 'msg'}
    for (kind, package, path), parts in zip(files, parsed):
        for part in parts:
            for field in part.fields:
                t = field.type
                if t.pkg_name is not None and (t.pkg_name, t.type) not in known:
                    fail('%s: field %s has type %s/%s, which no interface file defines'
                         % (path, field.name, t.pkg_name, t.type))
    check_dependencies(msgs_dir, own_package, files, parsed)

    out = [
        {
            'file': path.replace(os.sep, '/'),
            'kind': kind,
            'package': package,
            'parts': [message_json(p) for p in parts],
        }
        for (kind, package, path), parts in zip(files, parsed)
    ]
    json.dump(out, sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write('\n')


if __name__ == '__main__':
    main()
