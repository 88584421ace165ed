"""simulation: Monte Carlo rock fall trajectories on 2-D slope profiles (after Wyllie 2014, ch. 3-7)."""
__version__ = "0.1.0"
