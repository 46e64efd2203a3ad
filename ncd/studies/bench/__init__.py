"""Benchmarks of the solver: micro-benchmarks (:mod:`.solver`), the finishing stage (:mod:`.finish`),
the peer engine (:mod:`.peer`) and the bench page (:mod:`.page`)."""
