"""Layer 6, figures: the run figures, the resonance map and the runnability map, drawn
from results (plotting never runs a simulation)."""
