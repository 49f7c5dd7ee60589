#!/bin/sh
# Runs on the robot, started by `tafel deploy` over SSH after it copied the release into $TARGET/stage.
# Installs the release into its own virtual environment, checks that it imports, switches
# $TARGET/current to it and (re)starts the program. Any failure leaves the robot on the release it had.
# Settings come from the environment: TARGET PYTHON DEPENDENCIES SERVICE COMMAND START_TIMEOUT_S
# START_CHECK_S MIN_FREE_MB. A `run` program counts as started when it reports that each of its contexts
# ran a frame (its --ready-file; under systemd READY=1), not after a fixed wait: on a slow robot a broken
# release can take longer to fail than any timer.
set -eu
cd "$TARGET"
RELEASE=$(cat stage/RELEASE)
NEW="releases/$RELEASE"
PREVIOUS=$(readlink current 2>/dev/null || true)
mkdir -p releases

fail() { echo "$1" >&2; exit 1; }

free_mb=$(df -Pk . | awk 'NR==2 {print int($4 / 1024)}')
need_mb=$(du -sk stage | awk '{print int($1 / 1024) * 3}')
[ "$free_mb" -ge $((need_mb + MIN_FREE_MB)) ] || fail "not enough space on the robot: ${free_mb} MB free in $TARGET, about $((need_mb + MIN_FREE_MB)) MB needed; the robot keeps ${PREVIOUS:-no release}"

# a virtual environment cannot move: it is made in place, and counts once it has its INSTALLED mark
if [ ! -f "$NEW/INSTALLED" ]; then
    rm -rf "$NEW"
    if [ "$DEPENDENCIES" = robot ]; then
        # the packages of the Python named (the system's, or an environment made on the robot): a .pth line
        "$PYTHON" -m venv "$NEW" || fail "cannot make a virtual environment with $PYTHON"
        site=$("$NEW/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
        "$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])' >"$site/robot-python.pth"
        "$NEW/bin/pip" install -q --no-index --no-deps stage/wheels/tafel-*.whl >install.log 2>&1 \
            || { tail -n 3 install.log >&2; rm -rf "$NEW"; fail "installing release $RELEASE failed; the robot keeps ${PREVIOUS:-no release}"; }
    else
        "$PYTHON" -m venv "$NEW" || fail "cannot make a virtual environment with $PYTHON"
        "$NEW/bin/pip" install -q --no-index --find-links stage/wheels --no-deps stage/wheels/*.whl >install.log 2>&1 \
            || { tail -n 3 install.log >&2; rm -rf "$NEW"; fail "installing release $RELEASE failed; the robot keeps ${PREVIOUS:-no release}"; }
    fi
    cp -R stage/config "$NEW/config"
    cp stage/RELEASE "$NEW/RELEASE"
    "$NEW/bin/tafel" --help >/dev/null 2>install.log \
        || { tail -n 3 install.log >&2; rm -rf "$NEW"; fail "release $RELEASE does not start (tafel --help failed); the robot keeps ${PREVIOUS:-no release}"; }
    touch "$NEW/INSTALLED"
    echo "installed release $RELEASE"
else
    echo "release $RELEASE was installed already"
fi

stop_program() {
    if [ "$SERVICE" = systemd ]; then
        systemctl --user stop tafel.service 2>/dev/null || true
    elif [ -f tafel.pid ]; then
        pid=$(cat tafel.pid)
        if kill "$pid" 2>/dev/null; then
            i=0
            while kill -0 "$pid" 2>/dev/null && [ $i -lt 150 ]; do sleep 0.1; i=$((i + 1)); done
            kill -9 "$pid" 2>/dev/null || true
        fi
        rm -f tafel.pid
    fi
}

reports_ready() {  # $1: tafel's arguments; only `run` reports its start
    case "$1" in run|run\ *) return 0 ;; *) return 1 ;; esac
}

start_program() {  # $1: the release folder the program runs from, $2: tafel's arguments, $3: "ready" to ask for the report
    rm -f tafel.ready
    ready_argument=""
    [ "${3:-}" = ready ] && ready_argument="--ready-file $TARGET/tafel.ready"
    if [ "$SERVICE" = systemd ]; then
        mkdir -p "$HOME/.config/systemd/user"
        service_type=simple
        [ -n "$ready_argument" ] && service_type=notify
        cat >"$HOME/.config/systemd/user/tafel.service" <<UNIT
[Unit]
Description=Tafel robot control program

[Service]
Type=$service_type
NotifyAccess=main
TimeoutStartSec=$START_TIMEOUT_S
WorkingDirectory=$TARGET
ExecStart=$TARGET/current/bin/tafel $2 --config $TARGET/current/config $ready_argument
Restart=on-failure

[Install]
WantedBy=default.target
UNIT
        # with Type=notify this waits for READY=1; a failed start is judged below, not by set -e
        systemctl --user daemon-reload && systemctl --user restart tafel.service || true
    else
        # shellcheck disable=SC2086 - the arguments are words
        nohup "$TARGET/$1/bin/tafel" $2 --config "$TARGET/$1/config" $ready_argument >tafel.log 2>&1 </dev/null &
        echo $! >tafel.pid
    fi
}

running() {
    if [ "$SERVICE" = systemd ]; then
        systemctl --user is-active --quiet tafel.service
    else
        [ -f tafel.pid ] && kill -0 "$(cat tafel.pid)" 2>/dev/null
    fi
}

switch_to() { ln -sfn "$1" current; }

wait_until_ready() {  # until the program wrote tafel.ready, died, or START_TIMEOUT_S passed (systemctl waited already)
    [ "$SERVICE" = systemd ] && return 0
    deadline=$(( $(date +%s) + ${START_TIMEOUT_S%.*} + 1 ))
    while [ ! -f tafel.ready ]; do
        running || return 1
        [ "$(date +%s)" -lt "$deadline" ] || { echo "release $RELEASE did not report its start within ${START_TIMEOUT_S} s" >&2; return 1; }
        sleep 0.2
    done
}

PREVIOUS_COMMAND=$(cat current.command 2>/dev/null || echo "$COMMAND")
stop_program
switch_to "$NEW"
if reports_ready "$COMMAND"; then
    start_program "$NEW" "$COMMAND" ready
    started=0
    wait_until_ready && started=1
else
    start_program "$NEW" "$COMMAND"
    started=1
fi
[ "$started" = 1 ] && sleep "$START_CHECK_S"
if [ "$started" = 1 ] && running; then
    echo "$COMMAND" >current.command
    echo "running release $RELEASE (tafel $COMMAND)"
    exit 0
fi
echo "release $RELEASE did not start or did not keep running; its last lines:" >&2
tail -n 5 tafel.log >&2 2>/dev/null || true
stop_program
if [ -n "$PREVIOUS" ]; then
    switch_to "$PREVIOUS"
    start_program "$PREVIOUS" "$PREVIOUS_COMMAND"
    fail "release $RELEASE failed to start; the robot runs ${PREVIOUS#releases/} again"
fi
rm -f current
fail "release $RELEASE failed to start; the robot had no release before"
