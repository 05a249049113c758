"""``facelib dataset SPEC.toml -o DIR``: a synthetic face dataset, locally or on Dask."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from facelib.cli.console import EXIT_ERROR, EXIT_OK, Console
from facelib.cli.options import COMMON
from facelib.errors import ParameterError


def add(commands: Any) -> None:
    dataset = commands.add_parser(
        "dataset", parents=[COMMON],
        help="generate a synthetic face dataset from a SPEC.toml, locally or on Dask")
    dataset.add_argument("spec", help="the dataset spec (TOML, see docs/batch.md)")
    dataset.add_argument("-o", "--output", required=True, help="the dataset folder")
    dataset.add_argument("-j", "--jobs", type=int,
                         help="local processes (default: CPU count)")
    dataset.add_argument("--scheduler", metavar="ADDRESS",
                         help="a Dask scheduler: tcp://127.0.0.1:8786 on this machine, "
                              "tls://HOST:8786 on another (needs facelib[scale])")
    dataset.add_argument("--tls-ca", metavar="FILE",
                         help="with tls://: the CA certificate the cluster's are signed by")
    dataset.add_argument("--tls-cert", metavar="FILE", help="with tls://: this client's "
                         "certificate")
    dataset.add_argument("--tls-key", metavar="FILE", help="with tls://: its private key")
    dataset.add_argument("--trust-cluster", action="store_true",
                         help="the cluster and the network to it are yours: allow plain "
                              "tcp:// to another machine (results are still read as plain "
                              "data only)")
    dataset.set_defaults(run=_dataset)


def _dataset(args: argparse.Namespace, console: Console) -> int:
    from facelib.dataset import generate, load_spec

    security = _security(args)
    spec = load_spec(args.spec)
    report = generate(spec, args.output, jobs=args.jobs, scheduler=args.scheduler,
                      security=security, trust_cluster=args.trust_cluster,
                      progress=console.progress("dataset", unit="clips"))
    console.status(f"{args.output}: {report.written} clips written, {report.skipped} already "
                   f"there, {len(report.failed)} failed")
    for clip, error in report.failed:
        print(f"facelib: error: clip {clip}: {error}", file=sys.stderr)
    return EXIT_ERROR if report.failed else EXIT_OK



def _security(args: argparse.Namespace) -> Any:
    """Dask ``Security`` from ``--tls-ca``, ``--tls-cert`` and ``--tls-key`` (all three or
    none), or None."""
    tls = (args.tls_ca, args.tls_cert, args.tls_key)
    if args.scheduler is None and (any(tls) or args.trust_cluster):
        raise ParameterError("--tls-ca, --tls-cert, --tls-key and --trust-cluster need "
                             "--scheduler")
    if not any(tls):
        return None
    if not all(tls):
        raise ParameterError("TLS needs all of --tls-ca, --tls-cert and --tls-key")
    from facelib.cluster import tls_security

    return tls_security(ca=args.tls_ca, cert=args.tls_cert, key=args.tls_key)
