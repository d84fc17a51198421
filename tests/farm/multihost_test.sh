#!/bin/bash
# The farm across hosts, on one machine: two network namespaces with their
# own hostnames ("node-a", "node-b"), joined by a veth link (10.77.0.1 and
# .2), and Open MPI launching into them through an rsh agent exactly as a
# `mpirun --hostfile` across two machines would (../shared/MPI-NOTES.md).
# Checks:
#   1. the two ranks run on two machines and the image equals the local
#      render bit for bit;
#   2. a "node" killed mid-render fails the job (non-zero exit) after a
#      checkpoint was written, and the checkpoint resumes on one host to
#      the uninterrupted image.
# Needs root and `ip netns`; exits 77 (skipped) where namespaces cannot be
# made, as in unprivileged containers.
# Usage: multihost_test.sh TESSERA_BINARY SOURCE_DIR
set -u
TESSERA=$(readlink -f "$1")
SRC=$(readlink -f "$2")
WORK=$(mktemp -d /tmp/tessera_multihost.XXXXXX)
NS_A=tsr_mh_a_$$
NS_B=tsr_mh_b_$$
VETH=tmh$$

cleanup() {
  ip netns pids "$NS_A" 2>/dev/null | xargs -r kill -9 2>/dev/null
  ip netns pids "$NS_B" 2>/dev/null | xargs -r kill -9 2>/dev/null
  ip netns del "$NS_A" 2>/dev/null
  ip netns del "$NS_B" 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT

skip() { echo "skip: $*"; exit 77; }
fail() { echo "FAIL: $*"; exit 1; }

command -v mpirun >/dev/null || skip "no mpirun"
command -v ip >/dev/null || skip "no ip (iproute2)"
command -v unshare >/dev/null || skip "no unshare"
ip netns add "$NS_A" 2>/dev/null || skip "cannot create network namespaces (not root, or no CAP_SYS_ADMIN)"
ip netns add "$NS_B" || skip "cannot create a second network namespace"
ip link add "${VETH}a" type veth peer name "${VETH}b" 2>/dev/null || skip "cannot create a veth pair"
ip link set "${VETH}a" netns "$NS_A" && ip link set "${VETH}b" netns "$NS_B" || fail "moving the veth ends"
ip -n "$NS_A" addr add 10.77.0.1/24 dev "${VETH}a" && ip -n "$NS_B" addr add 10.77.0.2/24 dev "${VETH}b" ||
  fail "addressing the veth ends"
for ns in "$NS_A" "$NS_B"; do ip -n "$ns" link set lo up; done
ip -n "$NS_A" link set "${VETH}a" up && ip -n "$NS_B" link set "${VETH}b" up || fail "raising the link"
unshare --uts true 2>/dev/null || skip "cannot unshare the UTS namespace"

# Open MPI's rsh agent: AGENT [options] HOST COMMAND...
cat > "$WORK/agent.sh" <<EOF
#!/bin/sh
while [ \$# -gt 0 ]; do case "\$1" in -*) shift;; *) break;; esac; done
host=\$1; shift
case "\$host" in
  10.77.0.1) ns=$NS_A; name=node-a;;
  10.77.0.2) ns=$NS_B; name=node-b;;
  *) echo "agent: unknown host \$host" >&2; exit 1;;
esac
exec ip netns exec \$ns unshare --uts sh -c "hostname \$name; exec \$*"
EOF
chmod +x "$WORK/agent.sh"
printf "10.77.0.1 slots=1\n10.77.0.2 slots=1\n" > "$WORK/hosts"

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# mpirun itself runs on "node-a"; node-b's ranks start through the agent.
farm() {  # farm SECONDS HOSTFILE NP ARGS...
  local seconds=$1 hosts=$2 np=$3
  shift 3
  timeout "$seconds" ip netns exec "$NS_A" unshare --uts sh -c "hostname node-a; exec \"\$@\"" sh \
    mpirun --hostfile "$hosts" -np "$np" --mca plm_rsh_agent "$WORK/agent.sh" \
    --mca btl tcp,self --mca btl_tcp_if_include 10.77.0.0/24 --mca oob_tcp_if_include 10.77.0.0/24 \
    "$TESSERA" "$@"
}
identical() {  # identical A.exr B.exr: relMSE, RMSE and MAPE all exactly 0
  "$TESSERA" compare --json "$1" "$2" | grep -q '"relmse":0.0,"mape":0.0,"rmse":0.0,'
}

SCENE="$SRC/scenes/door-ajar.pbrt"
ARGS="$SCENE -q --no-preview --res 64x48 --seed 3"

# 1. Two hosts, one rank each: the same image as the local render.
"$TESSERA" render $ARGS --spp 10 -o "$WORK/local.exr" >/dev/null 2>&1 || fail "local render"
farm 120 "$WORK/hosts" 2 render $ARGS --spp 10 -o "$WORK/farm.exr" --stats "$WORK/farm.json" \
  >"$WORK/farm.log" 2>&1 || { cat "$WORK/farm.log"; fail "farm render across two hosts"; }
grep -Eq '"ranks": ?2\b' "$WORK/farm.json" || fail "stats: not 2 ranks"
grep -Eq '"machines": ?2\b' "$WORK/farm.json" || fail "stats: the ranks did not run on 2 machines"
identical "$WORK/farm.exr" "$WORK/local.exr" || fail "the two-host image differs from the local one"
echo "ok: 2 ranks on 2 hosts, image identical to the local render"

# 2. Kill node-b's rank after the first checkpoint, then resume on one host.
"$TESSERA" render $ARGS --spp 400 -o "$WORK/full.exr" >/dev/null 2>&1 || fail "uninterrupted local render"
farm 180 "$WORK/hosts" 2 render $ARGS --spp 400 -o "$WORK/killed.exr" \
  --checkpoint "$WORK/run.ckpt" --checkpoint-every 0 >"$WORK/killed.log" 2>&1 &
FARM=$!
for _ in $(seq 1 600); do
  [ -s "$WORK/run.ckpt" ] && break
  sleep 0.05
done
[ -s "$WORK/run.ckpt" ] || { kill -9 $FARM 2>/dev/null; fail "no checkpoint appeared"; }
VICTIM=$(ip netns pids "$NS_B" | while read -r p; do
  [ "$(cat /proc/$p/comm 2>/dev/null)" = tessera ] && echo "$p"; done | head -1)
[ -n "$VICTIM" ] || { kill -9 $FARM 2>/dev/null; fail "no tessera rank found on node-b"; }
kill -9 "$VICTIM"
wait $FARM
RC=$?
[ $RC -ne 0 ] || fail "the farm exited 0 after losing node-b"
[ -s "$WORK/run.ckpt" ] || fail "the checkpoint is gone"
printf "10.77.0.1 slots=1\n" > "$WORK/one_host"
farm 180 "$WORK/one_host" 1 render $ARGS --spp 400 -o "$WORK/resumed.exr" --resume "$WORK/run.ckpt" \
  >"$WORK/resume.log" 2>&1 || { cat "$WORK/resume.log"; fail "resume on one host"; }
identical "$WORK/resumed.exr" "$WORK/full.exr" || fail "the resumed image differs from the uninterrupted one"
echo "ok: node-b killed mid-render (exit $RC), resumed on node-a alone: image identical"
exit 0
