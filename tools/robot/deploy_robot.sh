#!/bin/sh
# Runs on the robot, started by `tafel deploy` over SSH after it copied the release into $TARGET/stage.
# Installs the release into its own virtual environment, checks that it imports, switches
# $TARGET/current to it and (re)starts the program. Any failure leaves the robot on the release it had.
# Settings come from the environment: TARGET PYTHON DEPENDENCIES SERVICE COMMAND START_CHECK_S MIN_FREE_MB.
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

start_program() {  # $1: the release folder the program runs from, $2: tafel's arguments
    if [ "$SERVICE" = systemd ]; then
        mkdir -p "$HOME/.config/systemd/user"
        cat >"$HOME/.config/systemd/user/tafel.service" <<UNIT
[Unit]
Description=Tafel robot control program

[Service]
WorkingDirectory=$TARGET
ExecStart=$TARGET/current/bin/tafel $2 --config $TARGET/current/config
Restart=on-failure

[Install]
WantedBy=default.target
UNIT
        systemctl --user daemon-reload && systemctl --user restart tafel.service
    else
        # shellcheck disable=SC2086 - the arguments are words
        nohup "$TARGET/$1/bin/tafel" $2 --config "$TARGET/$1/config" >tafel.log 2>&1 </dev/null &
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

PREVIOUS_COMMAND=$(cat current.command 2>/dev/null || echo "$COMMAND")
stop_program
switch_to "$NEW"
start_program "$NEW" "$COMMAND"
sleep "$START_CHECK_S"
if running; then
    echo "$COMMAND" >current.command
    echo "running release $RELEASE (tafel $COMMAND)"
    exit 0
fi
echo "release $RELEASE did not keep running; its last lines:" >&2
tail -n 5 tafel.log >&2 2>/dev/null || true
stop_program
if [ -n "$PREVIOUS" ]; then
    switch_to "$PREVIOUS"
    start_program "$PREVIOUS" "$PREVIOUS_COMMAND"
    fail "release $RELEASE failed to start; the robot runs ${PREVIOUS#releases/} again"
fi
rm -f current
fail "release $RELEASE failed to start; the robot had no release before"
