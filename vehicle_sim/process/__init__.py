"""Server plumbing: outbox, pacing, truth link, signals. Imports: link, procs, world, dynamics."""
