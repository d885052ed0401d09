#!/usr/bin/env bash
# Runs a sharded bake on a Kubernetes cluster: the volume, the Indexed Job of shards, a wait for
# it to complete, then the merge Job. The scene must already be on the volume (docs/distributed.md
# shows how to copy it there). Extra kubectl options (context, namespace) go in KUBECTL_OPTIONS.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
read -r -a options <<<"${KUBECTL_OPTIONS:-}"
kubectl "${options[@]}" apply -f "$here/volume.yaml"
kubectl "${options[@]}" apply -f "$here/bake-job.yaml"
kubectl "${options[@]}" wait --for=condition=complete job/shadowbake-bake --timeout=24h
kubectl "${options[@]}" apply -f "$here/merge-job.yaml"
kubectl "${options[@]}" wait --for=condition=complete job/shadowbake-merge --timeout=2h
