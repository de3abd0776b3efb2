#!/usr/bin/env bash
# Runs a command with an ssh server of its own on this machine (Debian's openssh-server, on a
# loopback port, keys made in DIR), stopped after it: DAYFLUX_TEST_SSH is the ssh command that
# logs in to it, DAYFLUX_TEST_SSH_LOGIN the login. For the GNU parallel recipe over ssh hosts in
# docs/shards.md; needs root (sshd's privilege separation directory).
# usage: local_sshd.sh DIR command...
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 DIR command..." >&2; exit 2; }
dir=$(mkdir -p "$1" && cd "$1" && pwd)
shift
[ -x /usr/sbin/sshd ] && command -v ssh >/dev/null ||
    { echo "$0: openssh-server is not installed (tools/setup.sh --tests installs it)" >&2; exit 3; }
mkdir -p /run/sshd
port=$((30000 + ($$ % 20000)))
rm -f "$dir/host_key" "$dir/user_key"
ssh-keygen -q -t ed25519 -N "" -f "$dir/host_key"
ssh-keygen -q -t ed25519 -N "" -f "$dir/user_key"
cp "$dir/user_key.pub" "$dir/authorized_keys"
chmod 600 "$dir/authorized_keys"
cat >"$dir/sshd_config" <<CONF
Port $port
ListenAddress 127.0.0.1
HostKey $dir/host_key
PidFile $dir/sshd.pid
AuthorizedKeysFile $dir/authorized_keys
PasswordAuthentication no
PermitRootLogin prohibit-password
StrictModes no
UsePAM no
CONF
stop() { [ -s "$dir/sshd.pid" ] && kill "$(cat "$dir/sshd.pid")" 2>/dev/null || true; }
trap stop EXIT
/usr/sbin/sshd -f "$dir/sshd_config" -E "$dir/sshd.log"
export DAYFLUX_TEST_SSH="ssh -p $port -i $dir/user_key -o StrictHostKeyChecking=no \
-o UserKnownHostsFile=/dev/null -o LogLevel=ERROR -o BatchMode=yes"
export DAYFLUX_TEST_SSH_LOGIN="$(id -un)@127.0.0.1"
for _ in $(seq 1 50); do
    $DAYFLUX_TEST_SSH "$DAYFLUX_TEST_SSH_LOGIN" true 2>/dev/null && break
    sleep 0.1
done
"$@"
