#!/usr/bin/env bash
# Install and appliance checks (docs/deploy.md) that need no package: the udev
# rules parse (udevadm verify where this udev has it, else check_udev_rules.py),
# the systemd units pass `systemd-analyze verify`, `marionette doctor` reports in
# text and valid JSON with the documented fields and exit codes (also as an
# unprivileged user), and `run` says which configuration files it read, in the
# documented search order.
# Usage: packaging_tests.sh MARIONETTE_BINARY SOURCE_DIR
set -uo pipefail
bin=$1
src=$2
source "$src/tests/cli/check_lib.sh"
rules=$src/packaging/udev/70-marionette.rules

# --- udev rules ---
if udevadm verify --help >/dev/null 2>&1; then
  check "udevadm verify accepts the rules" udevadm verify --no-style "$rules"
elif command -v udevadm >/dev/null 2>&1 && [[ -e /sys/class/net/lo ]] && unshare -m true 2>/dev/null; then
  # udev 252 (Debian 12) has no verify: let udev's own parser read the file via
  # `udevadm test`, in a private mount namespace whose /run holds only this rule
  # (nothing on the system changes). The group is unknown until postinst creates it.
  mkdir udev_rules && cp "$rules" udev_rules/
  unshare -m sh -c "mount -t tmpfs tmpfs /run && mkdir -p /run/udev/rules.d && cp udev_rules/70-marionette.rules /run/udev/rules.d/ && udevadm test --action=add /sys/class/net/lo" >udev_test.txt 2>&1
  check "udevadm test read the rules file" grep -q "Reading rules file: /run/udev/rules.d/70-marionette.rules" udev_test.txt
  grep "70-marionette.rules:[0-9]" udev_test.txt | grep -v "Unknown group 'marionette', ignoring" >udev_errors.txt
  cat udev_errors.txt
  check "udev's parser reports nothing about the rules (but the group postinst creates)" test ! -s udev_errors.txt
  # The same path finds a real error.
  printf 'KERNEL=="hidraw*", FOO=="x", GROUP="marionette"\n' >udev_rules/70-marionette.rules
  unshare -m sh -c "mount -t tmpfs tmpfs /run && mkdir -p /run/udev/rules.d && cp udev_rules/70-marionette.rules /run/udev/rules.d/ && udevadm test --action=add /sys/class/net/lo" >udev_bad.txt 2>&1
  check "udev's parser flags a bad key the same way" grep -q "70-marionette.rules:1 Invalid key 'FOO'" udev_bad.txt
else
  echo "neither udevadm verify nor udevadm test in a mount namespace available: the syntax check only"
fi
check "udev rules parse (check_udev_rules.py)" python3 "$src/tests/packaging/check_udev_rules.py" "$rules"
printf 'KERNEL=="hidraw*", MODE="rw"\n' >bad.rules
check "the rules checker rejects a bad rule" test "$(python3 "$src/tests/packaging/check_udev_rules.py" bad.rules | grep -c 'not octal')" -eq 1

# --- systemd units ---
# The system unit in a scratch root holding /usr/bin/marionette and this
# machine's own units (sysinit.target, ...), so ExecStart is checked too. The
# user unit: `--user` verify has no --root, so a copy whose ExecStart names this
# binary (the only difference) is verified as a file. Unknown keys exit 0 with a
# message, so the checks also require no output.
if command -v systemd-analyze >/dev/null 2>&1 && [[ -d /usr/lib/systemd/system ]]; then
  mkdir -p root/usr/bin root/usr/lib/systemd user_unit runtime && chmod 700 runtime
  cp "$bin" root/usr/bin/marionette
  cp -r /usr/lib/systemd/system root/usr/lib/systemd/
  cp "$src/packaging/systemd/marionette.service" root/usr/lib/systemd/system/
  systemd-analyze verify --root="$PWD/root" marionette.service >verify.txt 2>&1
  rc=$?
  cat verify.txt
  check "systemd-analyze verify marionette.service: exit 0" test $rc -eq 0
  check "systemd-analyze verify marionette.service: no messages" test ! -s verify.txt
  sed "s|^ExecStart=/usr/bin/marionette |ExecStart=$bin |" "$src/packaging/systemd/marionette-user.service" \
    >user_unit/marionette-user.service
  check "the user unit's ExecStart is /usr/bin/marionette" grep -q "^ExecStart=/usr/bin/marionette run " \
    "$src/packaging/systemd/marionette-user.service"
  XDG_RUNTIME_DIR=$PWD/runtime systemd-analyze verify --user user_unit/marionette-user.service >verify_user.txt 2>&1
  rc=$?
  cat verify_user.txt
  check "systemd-analyze verify --user marionette-user.service: exit 0" test $rc -eq 0
  check "systemd-analyze verify --user marionette-user.service: no messages" test ! -s verify_user.txt
  # The same check catches a typo.
  sed 's/^WatchdogSec=/WatchdogSecs=/' "$src/packaging/systemd/marionette.service" >root/usr/lib/systemd/system/marionette.service
  check "systemd-analyze verify reports an unknown key" bash -c "systemd-analyze verify --root='$PWD/root' marionette.service 2>&1 | grep -q \"Unknown key 'WatchdogSecs'\""
else
  echo "systemd-analyze not available: units not verified"
  [[ ${CI:-} != true ]] || check "CI has systemd-analyze" false
fi

# --- doctor ---
mkdir -p state xdg etc
export XDG_STATE_HOME=$PWD/state XDG_CONFIG_HOME=$PWD/xdg MARIONETTE_SYSCONFDIR=$PWD/etc
"$bin" doctor --json --rate-window 0.1 >doctor.json
rc=$?
check "doctor --json: exit 0 (no problems on this machine)" test $rc -eq 0
check "doctor --json: one valid JSON object with the documented fields" python3 - doctor.json <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for key in ("ok", "user", "groups", "pads", "display", "realtime", "memlock", "recordings", "config", "problems", "warnings"):
    assert key in d, key
assert d["ok"] is True and d["problems"] == []
assert d["display"]["request"] == "auto" and d["display"]["choice"] in ("headless", "window", "kms")
for k in ("allowed", "capability", "unlimited", "limit"):
    assert k in d["realtime"] and k in d["memlock"], k
assert d["recordings"]["dir"].endswith("/state/marionette/recordings"), d["recordings"]
assert d["recordings"]["writable"] is True and d["recordings"]["free_bytes"] > 0
names = [c["name"] for c in d["config"]]
assert names == ["marionette.toml", "render.toml"], names
assert all(c["origin"] == "built-in" and c["file"] is None and c["error"] is None for c in d["config"])
for p in d["pads"]:
    assert set(p) >= {"path", "backend", "readable", "problem", "report_rate_hz"}
    assert p["readable"] or p["problem"]
PY
"$bin" doctor >doctor.txt
check "doctor: text report ends with the verdict" grep -q '^ok: marionette can run$' doctor.txt
check "doctor: text report names the display path run would take" grep -q '^display: run --display auto would take ' doctor.txt

# A broken configuration file is a problem: exit 1, listed, JSON still valid.
printf '[locomotion]\nmax_speed = "fast"\n' >xdg/broken.toml
mkdir -p xdg/marionette && cp xdg/broken.toml xdg/marionette/marionette.toml
"$bin" doctor --json --rate-window 0 >bad.json
rc=$?
check "doctor: a broken user config: exit 1" test $rc -eq 1
check "doctor: a broken user config is the listed problem" python3 -c "
import json,sys; d=json.load(open('bad.json')); assert d['ok'] is False
assert len(d['problems'])==1 and 'marionette.toml:2: locomotion.max_speed' in d['problems'][0], d['problems']
c=d['config'][0]; assert c['origin']=='user' and c['file'].endswith('/xdg/marionette/marionette.toml'), c"
rm -r xdg/marionette
# --display kms without a usable DRM device is a problem (this machine has none under /dev/dri).
if ! ls /dev/dri/card* >/dev/null 2>&1; then
  "$bin" doctor --display kms --rate-window 0 >kms.txt
  rc=$?
  check "doctor --display kms without /dev/dri: exit 1" test $rc -eq 1
  check "doctor --display kms: says why in one line" grep -q '^  display: --display kms would fail: asked for by name; no usable KMS output: no /dev/dri/card\*$' kms.txt
fi
# Unprivileged: as nobody (when this runs as root), still a valid report.
if [[ $(id -u) -eq 0 ]] && command -v setpriv >/dev/null 2>&1; then
  chmod 755 "$work"; chmod 777 state
  setpriv --reuid=nobody --regid=nogroup --clear-groups "$bin" doctor --json --rate-window 0 >nobody.json
  rc=$?
  check "doctor as nobody: exit 0" test $rc -eq 0
  check "doctor as nobody: reports user nobody" python3 -c "import json; d=json.load(open('nobody.json')); assert d['user']=='nobody', d['user']"
fi

# A pad doctor can see: the Xbox 360 pad of tests/data/umockdev under umockdev
# (the real sysfs enumeration, the BTN_GAMEPAD capability test, open and the
# report-rate window on a replayed event stream).
if command -v umockdev-run >/dev/null 2>&1; then
  data=$src/tests/data/umockdev
  "$bin" sim-pad --format evemu --pad xbox --rate 1000 --program "$src/tests/data/programs/umockdev_pad.prog" \
    --out xbox.events >/dev/null
  timeout 30 umockdev-run -d "$data/xbox.umockdev" -i "/dev/input/event7=$data/xbox.ioctl" \
    -e "/dev/input/event7=xbox.events" -- "$bin" doctor --json --rate-window 0.5 >pad.json 2>/dev/null
  rc=$?
  check "doctor under umockdev: exit 0" test $rc -eq 0
  check "doctor under umockdev: the pad is listed, readable, with a measured report rate" python3 -c "
import json; d=json.load(open('pad.json')); p=d['pads']
assert len(p)==1, p; p=p[0]
assert (p['path'],p['backend'],p['vendor_id'],p['product_id'])==('/dev/input/event7','evdev','045e','028e'), p
assert p['readable'] and p['problem'] is None and p['reports']>0 and p['report_rate_hz']>0, p
assert not any('no pad' in w for w in d['warnings']), d['warnings']"
fi

# --- run: which configuration it read ---
"$bin" run --fast --duration 0.2 >run_default.txt
check "run says it uses the built-in defaults" grep -qF "marionette: configuration: the built-in defaults (no $XDG_CONFIG_HOME/marionette/marionette.toml, $MARIONETTE_SYSCONFDIR/marionette.toml)" run_default.txt
printf '[locomotion]\nmax_speed = 2.5\n' >etc/marionette.toml
"$bin" run --fast --duration 0.2 >run_etc.txt
check "run reads the system file" grep -qF "marionette: configuration: $MARIONETTE_SYSCONFDIR/marionette.toml (system) over the built-in defaults" run_etc.txt
mkdir -p xdg/marionette && printf '[locomotion]\nmax_speed = 2.0\n' >xdg/marionette/marionette.toml
"$bin" run --fast --duration 0.2 >run_user.txt
check "the user's file wins over the system's" grep -qF "marionette: configuration: $XDG_CONFIG_HOME/marionette/marionette.toml (user)" run_user.txt
printf '[locomotion]\nmax_speed = 1.5\n' >given.toml
"$bin" run --fast --duration 0.2 --config given.toml >run_given.txt
check "--config wins over both" grep -qF "marionette: configuration: given.toml (--config)" run_given.txt
cp xdg/broken.toml xdg/marionette/marionette.toml
expect_error "run with a broken user file names it and exits 2" 2 "$XDG_CONFIG_HOME/marionette/marionette.toml:2: locomotion.max_speed" \
  "$bin" run --fast --duration 0.2
# The file found is really applied: the same run with the user's max_speed
# differs from the defaults' (the demo walks at full stick).
printf '[locomotion]\nmax_speed = 0.5\n' >xdg/marionette/marionette.toml
"$bin" run --fast --duration 2 --stats-json slow.json >/dev/null
rm -r xdg/marionette etc/marionette.toml
"$bin" run --fast --duration 2 --stats-json default.json >/dev/null
check "the user's file changes the run (top speed capped at 0.5 m/s)" python3 -c "
import json; s=json.load(open('slow.json')); d=json.load(open('default.json'))
assert s['top_speed_m_s'] <= 0.5001 < d['top_speed_m_s'], (s['top_speed_m_s'], d['top_speed_m_s'])"

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
