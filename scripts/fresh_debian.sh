#!/usr/bin/env bash
# The README's commands on a fresh Debian image, as a newcomer runs them: a minimal Debian
# (debootstrap's minbase, what a container image holds) in a chroot, this checkout's committed
# files copied in (git archive HEAD), then
#   1. scripts/setup.sh, which must install the Vulkan driver and the C linker and then stop,
#      naming rustup, where Rust is missing;
#   2. Rust installed as that message says (rustup, default profile);
#   3. the first command: bash scripts/setup.sh && cargo run --release -- run scenarios/showcase.ron
#   4. with --tests: scripts/setup-tests.sh, then the tests named after it (all of them when
#      none is named: cargo test --workspace --locked).
# Each step's wall time is printed. Run as root on a Debian or Ubuntu machine:
#   bash scripts/fresh_debian.sh bookworm|trixie [--tests [CARGO TEST ARGS...]]
# The image stays in /var/tmp/flicker-fresh-RELEASE (FRESH_DIR overrides) for a second look;
# delete it to start again from nothing. A machine whose network goes through a proxy with its
# own certificate authority passes that on: SSL_CERT_FILE is copied in and named to curl, pip
# and npm.
set -euo pipefail
release="${1:?usage: fresh_debian.sh bookworm|trixie [--tests [CARGO TEST ARGS...]]}"
shift
tests=0
if [ "${1:-}" = --tests ]; then tests=1; shift; fi
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="${FRESH_DIR:-/var/tmp/flicker-fresh-$release}"

command -v debootstrap >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >/dev/null; }
if [ ! -e "$dir/etc/debian_version" ]; then
    echo "fresh_debian: debootstrap $release into $dir"
    debootstrap --variant=minbase "$release" "$dir" http://deb.debian.org/debian >"$dir.debootstrap.log" 2>&1 \
        || { echo "debootstrap failed; see $dir.debootstrap.log" >&2; exit 1; }
fi
mounted=()
cleanup() { for m in "${mounted[@]}"; do umount -R "$m" 2>/dev/null || umount -l "$m" 2>/dev/null || true; done; }
trap cleanup EXIT
for m in proc sys dev; do
    if ! mountpoint -q "$dir/$m"; then
        case $m in proc) mount -t proc proc "$dir/proc" ;; *) mount --rbind "/$m" "$dir/$m" ;; esac
        mounted+=("$dir/$m")
    fi
done
cp /etc/resolv.conf "$dir/etc/resolv.conf"
ca=""
if [ -n "${SSL_CERT_FILE:-}" ] && [ -f "$SSL_CERT_FILE" ]; then
    cp "$SSL_CERT_FILE" "$dir/tmp/outside-ca.crt"
    ca="export SSL_CERT_FILE=/tmp/outside-ca.crt CURL_CA_BUNDLE=/tmp/outside-ca.crt PIP_CERT=/tmp/outside-ca.crt REQUESTS_CA_BUNDLE=/tmp/outside-ca.crt NODE_EXTRA_CA_CERTS=/tmp/outside-ca.crt"
fi
rm -rf "$dir/root/flicker" && mkdir -p "$dir/root/flicker"
git -C "$root" archive HEAD | tar -x -C "$dir/root/flicker"
echo "fresh_debian: $(cat "$dir/etc/debian_version") at $(git -C "$root" rev-parse --short HEAD)"

inside() {
    chroot "$dir" /usr/bin/env -i HOME=/root TERM=dumb \
        PATH=/root/.cargo/bin:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
        /bin/bash -c "set -euo pipefail; $ca; cd /root/flicker; $1"
}
step() {
    local name="$1" start=$SECONDS
    echo "== $name"
    inside "$2"
    echo "== $name: $((SECONDS - start)) s"
}

# 1. Without Rust, setup.sh installs the driver and the linker, then stops and names rustup.
if ! inside 'command -v cargo' >/dev/null 2>&1; then
    echo "== setup.sh without Rust"
    if inside 'bash scripts/setup.sh' 2>"$dir/tmp/setup.err"; then
        echo "setup.sh succeeded without Rust; expected it to stop and name rustup" >&2; exit 1
    fi
    grep -q rustup "$dir/tmp/setup.err" || { cat "$dir/tmp/setup.err" >&2; echo "setup.sh did not name rustup" >&2; exit 1; }
    inside 'command -v cc curl >/dev/null' || { echo "setup.sh left no cc or no curl" >&2; exit 1; }
    # 2. Rust as the message says (the installer script's own download, for networks that reach
    # static.rust-lang.org but not sh.rustup.rs).
    step "rustup" 'curl --proto "=https" --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y >/dev/null 2>&1 \
        || { curl --proto "=https" --tlsv1.2 -sSf -o /tmp/rustup-init https://static.rust-lang.org/rustup/dist/x86_64-unknown-linux-gnu/rustup-init \
             && chmod +x /tmp/rustup-init && /tmp/rustup-init -y >/dev/null; }; rustc --version'
fi
# 3. The first command, as the README gives it.
step "first command" 'bash scripts/setup.sh && cargo run --release -- run scenarios/showcase.ron --quiet && ls runs/showcase/report.html'
# 4. The tests' set-up, then the tests.
if [ $tests = 1 ]; then
    step "setup-tests.sh" 'bash scripts/setup-tests.sh'
    step "cargo test" "cargo test --workspace --locked $*"
fi
