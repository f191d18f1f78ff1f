"""vipvflow: VIPV yield of electric bus fleets in 3D cities."""
import os

__version__ = "0.1.0"

# Arrow tables that crossed processes (the workers' trip sums) may hold buffers off 8-byte
# alignment after unpickling: Acero (group_by, dataset scans) printed a warning to stderr for
# each; it copies such buffers instead, unless the user chose otherwise.  Arrow reads this
# once, at a process's first Acero plan, so it is set when vipvflow is imported.
os.environ.setdefault("ACERO_ALIGNMENT_HANDLING", "reallocate")
