#!/usr/bin/python3
"""Checks deploy/kubernetes/ with kubectl and by reading it.

`kubectl apply --dry-run=client` parses every manifest and maps each kind to its API resource,
which takes an API server's discovery answers even for a client-side dry run. So this starts a
stand-in on 127.0.0.1 that answers discovery for the kinds the manifests use (v1
PersistentVolumeClaim, batch/v1 Job) and "not found" for every object, and runs kubectl against
it with --validate=false (schema validation needs the OpenAPI documents only a real cluster
serves). Then it reads the manifests itself: the bake Job is an Indexed Job whose completions,
parallelism and `--shard auto/N` agree, its output folder is indexed by JOB_COMPLETION_INDEX, the
merge names every shard folder, and both mount the claim volume.yaml makes.

    /usr/bin/python3 tests/distributed/kubernetes_manifests_test.py   (CTest: Distributed.KubernetesManifests)
"""

import http.server
import json
import pathlib
import re
import shutil
import subprocess
import sys
import threading

import yaml

ROOT = pathlib.Path(__file__).resolve().parents[2]
MANIFESTS = ROOT / "deploy" / "kubernetes"

RESOURCES = {
    "/api/v1": {"kind": "APIResourceList", "groupVersion": "v1", "resources": [
        {"name": "persistentvolumeclaims", "singularName": "persistentvolumeclaim",
         "namespaced": True, "kind": "PersistentVolumeClaim",
         "verbs": ["create", "get", "list", "patch", "update", "delete"]},
        {"name": "namespaces", "singularName": "namespace", "namespaced": False,
         "kind": "Namespace", "verbs": ["get", "list"]}]},
    "/apis/batch/v1": {"kind": "APIResourceList", "groupVersion": "batch/v1", "resources": [
        {"name": "jobs", "singularName": "job", "namespaced": True, "kind": "Job",
         "verbs": ["create", "get", "list", "patch", "update", "delete"]}]},
    "/api": {"kind": "APIVersions", "versions": ["v1"],
             "serverAddressByClientCIDRs": [{"clientCIDR": "0.0.0.0/0",
                                             "serverAddress": "127.0.0.1"}]},
    "/apis": {"kind": "APIGroupList", "apiVersion": "v1", "groups": [
        {"name": "batch", "versions": [{"groupVersion": "batch/v1", "version": "v1"}],
         "preferredVersion": {"groupVersion": "batch/v1", "version": "v1"}}]},
    "/version": {"major": "1", "minor": "30", "gitVersion": "v1.30.0"},
}


class Discovery(http.server.BaseHTTPRequestHandler):
    def do_GET(self):
        path = self.path.split("?")[0]
        if path in RESOURCES:
            self.reply(200, RESOURCES[path])
        else:
            self.reply(404, {"kind": "Status", "apiVersion": "v1", "status": "Failure",
                             "reason": "NotFound", "code": 404, "message": f"{path} not found"})

    def reply(self, code, body):
        data = json.dumps(body).encode()
        self.send_response(code)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)

    def log_message(self, *args):
        pass


def check_manifests(failures):
    docs = {p.name: list(yaml.safe_load_all(p.read_text())) for p in sorted(MANIFESTS.glob("*.yaml"))}
    claim = docs["volume.yaml"][0]
    bake = docs["bake-job.yaml"][0]
    merge = docs["merge-job.yaml"][0]
    spec = bake["spec"]
    if spec.get("completionMode") != "Indexed":
        failures.append("bake-job.yaml: not an Indexed Job")
    command = " ".join(spec["template"]["spec"]["containers"][0]["command"])
    shard = re.search(r"--shard auto/(\d+)", command)
    if not shard:
        failures.append("bake-job.yaml: no --shard auto/N")
        return
    n = int(shard.group(1))
    if not (spec.get("completions") == spec.get("parallelism") == n):
        failures.append(f"bake-job.yaml: completions {spec.get('completions')}, parallelism "
                        f"{spec.get('parallelism')} and --shard auto/{n} disagree")
    if "shard_$JOB_COMPLETION_INDEX" not in command:
        failures.append("bake-job.yaml: the output folder is not indexed by JOB_COMPLETION_INDEX")
    merge_command = merge["spec"]["template"]["spec"]["containers"][0]["command"]
    folders = [a for a in merge_command if a.startswith("/data/work/shard_")]
    if folders != [f"/data/work/shard_{k}" for k in range(n)]:
        failures.append(f"merge-job.yaml: merges {folders}, not the {n} shards")
    for name, job in (("bake-job.yaml", bake), ("merge-job.yaml", merge)):
        claims = [v["persistentVolumeClaim"]["claimName"]
                  for v in job["spec"]["template"]["spec"]["volumes"]]
        if claims != [claim["metadata"]["name"]]:
            failures.append(f"{name}: mounts {claims}, not {claim['metadata']['name']}")
    print(f"kubernetes: {n} shards, Indexed Job, merge of every shard, one shared claim")


def main():
    failures = []
    check_manifests(failures)
    kubectl = shutil.which("kubectl")
    if not kubectl:
        failures.append("kubectl not found (apt-get install kubernetes-client)")
    else:
        server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Discovery)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        url = f"http://127.0.0.1:{server.server_address[1]}"
        run = subprocess.run([kubectl, "--server", url, "--namespace", "default",
                              "apply", "--dry-run=client", "--validate=false",
                              "-f", str(MANIFESTS)], capture_output=True, text=True, timeout=120)
        server.shutdown()
        print(run.stdout.strip())
        expected = ["persistentvolumeclaim/shadowbake-data created (dry run)",
                    "job.batch/shadowbake-bake created (dry run)",
                    "job.batch/shadowbake-merge created (dry run)"]
        if run.returncode != 0:
            failures.append(f"kubectl apply --dry-run=client failed: {run.stderr.strip()}")
        for line in expected:
            if line not in run.stdout:
                failures.append(f"kubectl did not say: {line}")
    if failures:
        for f in failures:
            print("FAIL:", f, file=sys.stderr)
        sys.exit(1)
    print("kubernetes manifests: ok")


if __name__ == "__main__":
    main()
