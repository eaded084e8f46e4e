#!/bin/sh
# SPDX-License-Identifier: MIT
# mpirun's launcher (--mca plm_rsh_agent) for two simulated hosts on one machine
# (mpi_test.py hosts): instead of `ssh HOST COMMAND...` it runs COMMAND in the network namespace
# that owns HOST's address. WHITTED_NETNS_MAP="10.77.0.1=ns1 10.77.0.2=ns2" names them.
# Open MPI may put ssh-style options before the host; they are skipped.
while [ $# -gt 0 ]; do
    case "$1" in
        -*) shift ;;
        *) break ;;
    esac
done
host=$1
shift
for pair in $WHITTED_NETNS_MAP; do
    if [ "${pair%%=*}" = "$host" ]; then
        exec ip netns exec "${pair#*=}" /bin/sh -c "$*"
    fi
done
echo "netns_agent.sh: no namespace for host '$host' in WHITTED_NETNS_MAP='$WHITTED_NETNS_MAP'" >&2
exit 255
