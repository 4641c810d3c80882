#!/usr/bin/env bash
# The built package (docs/deploy.md, "Testing the package"):
#   package_tests.sh DEB            the light test: the layout `dpkg-deb -c`
#       lists, Depends/conffiles/maintainer scripts in the control data, then
#       `dpkg -x` into a scratch root and, as an unprivileged user (nobody, via
#       setpriv, when run as root), `marionette doctor --json` and
#       `marionette run --duration 3 --display headless` from that root.
#   package_tests.sh DEB ROOT       also installs the package with apt into ROOT,
#       a fresh Debian 12 root (`debootstrap --variant=minbase bookworm ROOT`;
#       the network is needed for the Depends), and runs the same two commands
#       there as the `marionette` user the postinst created. Needs root.
set -uo pipefail
deb=$(realpath "$1")
fresh_root=${2:-}
src=$(cd "$(dirname "$0")/../.." && pwd)
bin=unused
source "$src/tests/cli/check_lib.sh"

# --- contents and control data ---
dpkg-deb -c "$deb" | awk '{print $NF}' | sed 's|^\./|/|' >contents.txt
for path in /usr/bin/marionette /usr/share/marionette/marionette.toml /usr/share/marionette/render.toml \
            /usr/share/marionette/programs/demo.prog /usr/share/marionette/terrain/stairs.toml \
            /usr/share/marionette/clips/wave.bvh /etc/marionette/marionette.toml /etc/marionette/render.toml \
            /usr/lib/udev/rules.d/70-marionette.rules /usr/lib/systemd/system/marionette.service \
            /usr/lib/systemd/user/marionette-user.service /usr/share/doc/marionette/deploy.md; do
  check "package contains $path" grep -qx "$path" contents.txt
done
check "nothing under /usr/local or /usr/etc" test "$(grep -c '^/usr/local/\|^/usr/etc' contents.txt)" -eq 0
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for lib in libc6 libstdc++6 libegl1 libgles2 libseat1 libhidapi-hidraw0 libevdev2 libsystemd0 passwd; do
  check "Depends names $lib (from the linked libraries)" grep -q "\b$lib\b" <<<"$depends"
done
mkdir control && dpkg-deb -e "$deb" control
check "conffiles lists /etc/marionette/marionette.toml" grep -qx /etc/marionette/marionette.toml control/conffiles
check "postinst creates the marionette user" grep -q "useradd --system" control/postinst
check "postinst reloads udev" grep -q "udevadm control --reload-rules" control/postinst
check "maintainer scripts parse (sh -n)" sh -n control/postinst control/postrm

# --- extracted into a scratch root, run unprivileged ---
mkdir root && dpkg -x "$deb" root
as_user=()
if [[ $(id -u) -eq 0 ]]; then
  as_user=(setpriv --reuid=nobody --regid=nogroup --clear-groups)
  chmod 755 "$work"
fi
mkdir -m 777 state
env_vars=(env -i PATH=/usr/bin:/bin HOME=/nonexistent XDG_STATE_HOME="$work/state"
          MARIONETTE_SYSCONFDIR="$work/root/etc/marionette")
start=$(date +%s)
"${as_user[@]}" "${env_vars[@]}" root/usr/bin/marionette doctor --json --rate-window 0.2 >doctor.json 2>doctor.err
rc=$?
cat doctor.err
check "extracted: doctor --json exits 0" test $rc -eq 0
check "extracted: doctor --json is valid, unprivileged, reads the package's /etc file" python3 -c "
import json; d=json.load(open('doctor.json'))
assert d['ok'] is True, d['problems']
assert d['user'] == ('nobody' if $(id -u) == 0 else d['user']), d['user']
c = d['config'][0]; assert c['origin'] == 'system' and c['file'].endswith('/root/etc/marionette/marionette.toml'), c"
"${as_user[@]}" "${env_vars[@]}" root/usr/bin/marionette run --duration 3 --display headless --stats-json "$work/state/stats.json" >run.txt 2>run.err
rc=$?
cat run.txt run.err
check "extracted: run --duration 3 --display headless exits 0" test $rc -eq 0
check "extracted: run read the package's /etc/marionette/marionette.toml" grep -q "marionette: configuration: .*/root/etc/marionette/marionette.toml (system)" run.txt
check "extracted: run ticked 3 s" grep -q '"ticks":720' state/stats.json
echo "extracted-root checks: $(( $(date +%s) - start )) s"

# --- installed with apt into a fresh Debian 12 root ---
if [[ -n "$fresh_root" ]]; then
  start=$(date +%s)
  cp "$deb" "$fresh_root/tmp/marionette.deb"
  mount -t proc proc "$fresh_root/proc" 2>/dev/null && mounted=1 || mounted=0
  chroot "$fresh_root" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends /tmp/marionette.deb >apt.txt 2>&1
  rc=$?
  tail -5 apt.txt
  check "fresh root: apt installs the package and its Depends" test $rc -eq 0
  check "fresh root: postinst created the marionette user" chroot "$fresh_root" getent passwd marionette
  check "fresh root: and its group" chroot "$fresh_root" getent group marionette
  chroot "$fresh_root" sh -c 'mkdir -p /var/lib/marionette && chown marionette:marionette /var/lib/marionette'
  chroot "$fresh_root" runuser -u marionette -- env STATE_DIRECTORY=/var/lib/marionette marionette doctor --json --rate-window 0.2 >fresh_doctor.json
  rc=$?
  cat fresh_doctor.json
  check "fresh root: doctor --json as marionette exits 0" test $rc -eq 0
  check "fresh root: doctor ran as marionette and reads /etc/marionette" python3 -c "
import json; d=json.load(open('fresh_doctor.json')); assert d['user']=='marionette' and d['ok'], d
assert d['config'][0]['file'] == '/etc/marionette/marionette.toml', d['config']
assert d['recordings']['dir'] == '/var/lib/marionette/recordings' and d['recordings']['writable'], d['recordings']"
  chroot "$fresh_root" runuser -u marionette -- marionette run --duration 3 --display headless >fresh_run.txt 2>&1
  rc=$?
  cat fresh_run.txt
  check "fresh root: run --duration 3 --display headless as marionette exits 0" test $rc -eq 0
  check "fresh root: run reported 720 ticks" grep -q "demo finished: 3.0 s, 720 ticks" fresh_run.txt
  ((mounted)) && umount "$fresh_root/proc"
  echo "fresh-root install and checks: $(( $(date +%s) - start )) s"
fi

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
