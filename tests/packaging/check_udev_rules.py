#!/usr/bin/env python3
"""Syntax check of a udev rules file, for udev versions without `udevadm verify`
(Debian 12 has systemd 252; verify arrived in 253). Checks what udev's parser
rejects or silently ignores: unknown keys, an operator a key does not take,
unquoted or unterminated values, attributes without {name}, a bad MODE.
Usage: check_udev_rules.py FILE...  Exit 1 with one line per error."""
import re
import sys

MATCH_ONLY = {"ACTION", "DEVPATH", "KERNEL", "KERNELS", "SUBSYSTEM", "SUBSYSTEMS", "DRIVER", "DRIVERS",
              "ATTRS", "TAGS", "TEST", "PROGRAM", "RESULT", "CONST", "SYSCTL"}
ASSIGN_ONLY = {"OWNER", "GROUP", "MODE", "RUN", "LABEL", "GOTO", "OPTIONS", "SECLABEL", "IMPORT"}
BOTH = {"ENV", "ATTR", "TAG", "NAME", "SYMLINK"}
NEEDS_ATTRIBUTE = {"ATTR", "ATTRS", "ENV", "SYSCTL", "SECLABEL", "IMPORT", "CONST"}
TOKEN = re.compile(r'\s*([A-Z]+)(\{[^}"]+\})?\s*(==|!=|\+=|-=|:=|=)\s*"((?:[^"\\]|\\.)*)"\s*(,|$)')


def check_line(line):
    errors, pos, keys = [], 0, []
    while pos < len(line):
        m = TOKEN.match(line, pos)
        if not m:
            return [f"cannot parse at column {pos + 1}: {line[pos:pos + 30]!r}"]
        key, attr, op, value, sep = m.groups()
        keys.append(key)
        if key not in MATCH_ONLY | ASSIGN_ONLY | BOTH:
            errors.append(f"unknown key {key}")
        elif op in ("==", "!=") and key in ASSIGN_ONLY:
            errors.append(f"{key} cannot be matched ({op})")
        elif op not in ("==", "!=") and key in MATCH_ONLY:
            errors.append(f"{key} cannot be assigned ({op})")
        if key in NEEDS_ATTRIBUTE and key != "IMPORT" and not attr:
            errors.append(f"{key} needs {{attribute}}")
        if key == "MODE" and not re.fullmatch(r"0?[0-7]{3}", value):
            errors.append(f"MODE {value!r} is not octal")
        pos = m.end()
        if sep == "" and pos < len(line):
            return errors + [f"missing comma at column {pos + 1}"]
    if not any(k in ASSIGN_ONLY or k in BOTH for k in keys):
        errors.append("rule assigns nothing")
    return errors


def main(paths):
    failures = 0
    for path in paths:
        rules = 0
        with open(path, encoding="utf-8") as f:
            for number, raw in enumerate(f, 1):
                line = raw.rstrip("\n")
                if not line.strip() or line.lstrip().startswith("#"):
                    continue
                if line.endswith("\\"):
                    print(f"{path}:{number}: line continuations are not used here")
                    failures += 1
                    continue
                rules += 1
                for error in check_line(line):
                    print(f"{path}:{number}: {error}")
                    failures += 1
        print(f"{path}: {rules} rules, {failures} errors")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
