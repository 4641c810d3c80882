# Shared by the tuning UI's Xvfb end-to-end scripts (sourced, not run): a
# scratch working directory (removed on exit), the check counter, a small
# window without MSAA in a private HOME (llvmpipe draws it in a few ms on an
# idle machine; run reads render.toml from the user's configuration folder),
# run_in_window to start `marionette run --display window` under xvfb-run, and
# finish to print the summary and return the status.
# Needs: $bin, the marionette binary.
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
passes=0
failures=0
check() {
  local what=$1
  shift
  if "$@"; then passes=$((passes + 1)); else failures=$((failures + 1)); echo "FAIL: $what"; fi
}
if ! command -v xvfb-run >/dev/null; then
  echo "xvfb-run is not installed (scripts/setup.sh installs it)"
  exit 1
fi
mkdir -p home/.config/marionette
printf '[display]\nwidth = 640\nheight = 400\nmsaa_samples = 0\n' >home/.config/marionette/render.toml

# run_in_window ARGS...: `marionette run --display window ARGS` under Xvfb,
# stdout to run.txt, stderr to run.err; sets run_code.
run_in_window() {
  HOME=$work/home XDG_CONFIG_HOME=$work/home/.config LIBGL_ALWAYS_SOFTWARE=1 \
    xvfb-run -a -s "-screen 0 800x600x24" "$bin" run --display window "$@" >run.txt 2>run.err
  run_code=$?
}

# finish [FILE...]: on a failure, prints run.txt, run.err and the files; then the
# summary; returns 0 when every check passed.
finish() {
  if ((failures > 0)); then
    echo "--- run.txt"; cat run.txt; echo "--- run.err"; cat run.err
    local f
    for f in "$@"; do echo "--- $f"; cat "$f"; done
  fi
  echo "$passes passed, $failures failed"
  [[ $failures -eq 0 ]]
}
