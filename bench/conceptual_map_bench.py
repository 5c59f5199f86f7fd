"""Conceptual-map inference time: our loopy BP vs pgmpy exact inference, same run, same maps.

Maps are random buildings: corridor segments in a chain, rooms off them, a few extra
room-to-room doors (loops), 10 places per room with random property evidence and some objects.
Two exact references, both pgmpy, both every variable's marginal: variable elimination (one
query per variable) and junction-tree belief propagation (`BeliefPropagation`: one
calibration, then each marginal from a clique belief). pgmpy's own junction tree triangulates
with its H6 heuristic, which on a 50-room map asks for a 123 TiB clique table; the tree here
is built by pgmpy from a greedy min-fill elimination order, and calibrated by pgmpy's belief
update in one collect and one distribute pass (its calibrate() stops early on large maps: see
`junction_tree_marginals`). The time given is all of it (order, triangulation, tree,
calibration, marginals).
Run: `.venv/bin/python -m bench.conceptual_map_bench [--quick] [--sizes 10 50 ...]`.
"""

from __future__ import annotations

import argparse
import itertools
import statistics
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import networkx as nx
import numpy as np
from pgmpy.inference import BeliefPropagation
from pgmpy.models import DiscreteMarkovNetwork

from conceptual_map.conceptual import ConceptualMap, category_variable
from conceptual_map.conceptual.exact import exact_marginals, markov_network

PLACES_PER_ROOM = 10
LABELS = ("table", "counter", "desk", "shelf", "monitor", "cup", "book", "sink", "sofa")


@dataclass(frozen=True)
class Row:
    """One map size: timings in milliseconds (None where pgmpy was not run)."""

    rooms: int
    places: int
    edges: int
    full_ms: float
    full_best_ms: float
    incremental_ms: float
    iterations: int
    exact_ms: float | None
    max_error: float | None
    jt_ms: float | None = None
    jt_max_error: float | None = None
    jt_largest_clique: int | None = None


def random_building(rooms: int, seed: int) -> ConceptualMap:
    """A building map with `rooms` rooms and PLACES_PER_ROOM places each."""
    rng = np.random.default_rng(seed)
    cmap = ConceptualMap()
    knowledge = cmap.knowledge
    corridors = max(1, rooms // 8)
    names = [f"room{i}" for i in range(rooms)]
    for i, room in enumerate(names):
        for j in range(PLACES_PER_ROOM):
            place = f"{room}_p{j}"
            cmap.add_place(place, room)
            for kind, model in knowledge.properties.items():
                if rng.random() < 0.4:
                    cmap.observe_property(place, kind, str(rng.choice(model.values)))
        if i >= corridors:
            cmap.connect_rooms(room, names[int(rng.integers(corridors))])
        elif i > 0:
            cmap.connect_rooms(room, names[i - 1])
        if rng.random() < 0.5:
            cmap.observe_object(str(rng.choice(LABELS)), room)
    for _ in range(rooms // 10):
        a, b = rng.choice(np.arange(corridors, rooms), size=2, replace=False)
        cmap.connect_rooms(names[int(a)], names[int(b)])
    return cmap


def min_fill_order(network: DiscreteMarkovNetwork) -> list:
    """A greedy min-fill elimination order (ties: fewer neighbours, then name): eliminate
    the variable whose neighbours need the fewest new edges to become a clique."""
    graph = nx.Graph()
    graph.add_nodes_from(network.nodes())
    graph.add_edges_from(network.edges())

    def fill(v) -> int:
        nbrs = list(graph.neighbors(v))
        return sum(1 for a, b in itertools.combinations(nbrs, 2) if not graph.has_edge(a, b))

    cost = {v: fill(v) for v in graph.nodes}
    order = []
    while cost:
        node = min(cost, key=lambda v: (cost[v], graph.degree(v), str(v)))
        nbrs = list(graph.neighbors(node))
        graph.add_edges_from(itertools.combinations(nbrs, 2))
        graph.remove_node(node)
        del cost[node]
        order.append(node)
        touched = set(nbrs)
        for v in nbrs:
            touched.update(graph.neighbors(v))
        for v in touched:
            cost[v] = fill(v)
    return order


def junction_tree_marginals(factors) -> tuple[dict[str, np.ndarray], int]:
    """Normalised marginals of every variable by pgmpy's junction-tree BeliefPropagation (one
    calibration), and the largest clique's size. pgmpy builds the tree; only the
    triangulation's elimination order is ours (min-fill instead of its default H6)."""
    network = markov_network(factors)
    order = min_fill_order(network)
    # to_junction_tree() calls self.triangulate() with no arguments: give it the order
    network.triangulate = lambda *args, **kwargs: DiscreteMarkovNetwork.triangulate(
        network, order=order)
    tree = network.to_junction_tree()
    inference = BeliefPropagation(tree)
    # pgmpy's calibrate() starts a pass from each clique until its convergence test, which
    # compares factors with an absolute tolerance, finds the sepsets agree: the beliefs of
    # a 100-room map are ~1e-13, so it stops after one partial pass (92 of 100 marginals
    # wrong, by up to 0.9). Its belief update run in the two passes that calibrate a tree
    # (leaves to a root, then back) is exact.
    inference.clique_beliefs = {clique: tree.get_factors(clique) for clique in tree.nodes()}
    inference.sepset_beliefs = {frozenset(edge): None for edge in tree.edges()}
    if tree.number_of_nodes() > 1:
        edges = list(nx.bfs_edges(tree, next(iter(tree.nodes()))))
        for parent, child in reversed(edges):
            inference._update_beliefs(child, parent, operation="marginalize")
        for parent, child in edges:
            inference._update_beliefs(parent, child, operation="marginalize")
    marginals: dict[str, np.ndarray] = {}
    beliefs = inference.get_clique_beliefs()
    for clique, belief in beliefs.items():
        for variable in clique:
            if variable not in marginals:
                values = belief.marginalize([v for v in clique if v != variable],
                                            inplace=False).values
                marginals[variable] = values / values.sum()
    return marginals, max(len(clique) for clique in beliefs)


def timings_ms(action: Callable[[], object], repeats: int) -> list[float]:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        action()
        times.append((time.perf_counter() - start) * 1000.0)
    return times


def median_ms(action: Callable[[], object], repeats: int) -> float:
    return statistics.median(timings_ms(action, repeats))


def measure(rooms: int, exact_limit: int, repeats: int, seed: int,
            jt_limit: int | None = None) -> Row:
    jt_limit = exact_limit if jt_limit is None else jt_limit
    cmap = random_building(rooms, seed)
    full = timings_ms(lambda: cmap.update(cold=True), repeats)
    result = cmap.update(cold=True)
    counter = iter(range(10**9))

    def one_observation() -> None:
        place = f"room{next(counter) % rooms}_p0"
        cmap.observe_property(place, "appearance", "kitchen_like")
        cmap.update()

    incremental_ms = median_ms(one_observation, repeats)
    exact_ms, error, jt_ms, jt_error, largest = None, None, None, None, None
    cmap.update(cold=True)
    factors = cmap.factors(merged=True)

    def max_error(reference: dict[str, np.ndarray]) -> float:
        return max(float(np.abs(cmap.room_marginal(r) - reference[category_variable(r)]).max())
                   for r in cmap.graph.rooms)

    if rooms <= exact_limit:
        exact: dict[str, np.ndarray] = {}
        exact_ms = median_ms(lambda: exact.update(exact_marginals(factors)), 1)
        error = max_error(exact)
    if rooms <= jt_limit:
        tree: dict[str, np.ndarray] = {}
        sizes: list[int] = []

        def run_tree() -> None:
            marginals, size = junction_tree_marginals(factors)
            tree.update(marginals)
            sizes.append(size)

        jt_ms = median_ms(run_tree, 1)
        jt_error, largest = max_error(tree), sizes[-1]
    mrf, _ = cmap.graph.compile()
    return Row(rooms, rooms * PLACES_PER_ROOM, len(mrf.edges), statistics.median(full),
               min(full), incremental_ms,
               result.iterations, exact_ms, error, jt_ms, jt_error, largest)


def _reference(ms: float | None, full_ms: float, error: float | None) -> str:
    """`ms ratio error` columns of one exact reference ('not run' where it was not)."""
    if ms is None:
        return f"{'not run':>9} {'-':>7} {'-':>9}"
    return f"{ms:9.1f} {ms / full_ms:6.1f}x {error:9.2e}"


def print_table(rows: list[Row]) -> None:
    print(f"{'rooms':>5} {'places':>6} {'links':>5} {'ours full ms':>12} {'(best)':>7} "
          f"{'ours incr ms':>12} {'BP iters':>8} | {'VE ms':>9} {'VE/ours':>7} {'max |err|':>9} "
          f"| {'JT-BP ms':>9} {'JT/ours':>7} {'max |err|':>9} {'clique':>6} | {'VE/JT':>6}")
    for row in rows:
        both = row.exact_ms is not None and row.jt_ms is not None
        ve_over_jt = f"{row.exact_ms / row.jt_ms:5.1f}x" if both else f"{'-':>6}"
        clique = f"{row.jt_largest_clique:6d}" if row.jt_largest_clique else f"{'-':>6}"
        print(f"{row.rooms:5d} {row.places:6d} {row.edges:5d} {row.full_ms:12.2f} "
              f"{row.full_best_ms:7.2f} {row.incremental_ms:12.2f} {row.iterations:8d} | "
              f"{_reference(row.exact_ms, row.full_ms, row.max_error)} | "
              f"{_reference(row.jt_ms, row.full_ms, row.jt_max_error)} {clique} | "
              f"{ve_over_jt}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="sizes 10 and 50, fewer repeats")
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 50, 100, 300])
    parser.add_argument("--exact-limit", type=int, default=100,
                        help="largest map pgmpy exact inference is run on (300 rooms: a "
                             "single VE query alone takes minutes)")
    parser.add_argument("--jt-limit", type=int, default=None,
                        help="largest map junction-tree BP is run on (default: --exact-limit)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    sizes = [10, 50] if args.quick else args.sizes
    repeats = 3 if args.quick else 7
    warnings.simplefilter("ignore")
    rows = [measure(n, args.exact_limit, repeats, args.seed, args.jt_limit) for n in sizes]
    print("conceptual map inference (median of repeats; best in brackets): ours = compile "
          "chain graph + damped loopy BP (cold);")
    print("incr = one new observation then warm-started BP; exact references, same maps, same "
          "run: VE = pgmpy VariableElimination (one query per variable), JT-BP = pgmpy "
          "junction-tree BeliefPropagation (one calibration, min-fill triangulation; clique = "
          "its largest clique); ratios = reference / ours full; |err| = ours vs the reference "
          "over the room marginals")
    print_table(rows)
    if any(row.exact_ms is None or row.jt_ms is None for row in rows):
        print(f"pgmpy not run above {args.exact_limit} rooms (--exact-limit, --jt-limit): its "
              "exact inference grows too slow for this benchmark's budget")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
