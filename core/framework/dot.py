"""Graphviz DOT text for module graphs (one manager, or several contexts with their hand-overs)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _cluster_lines(graph: Mapping[str, Any], prefix: str) -> list[str]:
    """Nodes and edges of one manager's graph; node ids are prefixed so contexts can share a file."""
    context = graph["name"]
    lines = [f"  subgraph {_quote('cluster_' + context)} {{", f"    label={_quote(context)};"]
    for module in graph["modules"]:
        style = "solid" if module["active"] else "dashed"
        lines.append(f"    {_quote(prefix + module['name'])} [shape=box, style={style}, label={_quote(module['name'])}];")
    for rep, info in graph["representations"].items():
        shape = "ellipse" if info["provider"] else "doubleoctagon"
        lines.append(f"    {_quote(prefix + rep)} [shape={shape}, label={_quote(rep)}];")
    for module in graph["modules"]:
        if not module["active"]:
            continue
        name = _quote(prefix + module["name"])
        for rep in module["provides"]:
            if graph["representations"].get(rep, {}).get("provider") == module["name"]:
                lines.append(f"    {name} -> {_quote(prefix + rep)};")
        for rep in module["requires"]:
            lines.append(f"    {_quote(prefix + rep)} -> {name};")
        for rep in module["uses"]:
            lines.append(f"    {_quote(prefix + rep)} -> {name} [style=dashed];")
    lines.append("  }")
    return lines


def manager_dot(graph: Mapping[str, Any]) -> str:
    """DOT of one manager's graph: modules are boxes, representations ellipses (external: octagons)."""
    return "\n".join(["digraph tafel {", "  rankdir=LR;", *_cluster_lines(graph, graph["name"] + ":"), "}"]) + "\n"


def contexts_dot(graphs: Iterable[Mapping[str, Any]], handovers: Iterable[tuple[str, str, str]]) -> str:
    """DOT of several contexts; ``handovers`` are (representation, from context, to context)."""
    lines = ["digraph tafel {", "  rankdir=LR;", "  compound=true;"]
    for graph in graphs:
        lines += _cluster_lines(graph, graph["name"] + ":")
    for rep, source, target in handovers:
        lines.append(
            f"  {_quote(source + ':' + rep)} -> {_quote(target + ':' + rep)} "
            f"[style=bold, color=blue, label={_quote('hand-over')}];"
        )
    lines.append("}")
    return "\n".join(lines) + "\n"
