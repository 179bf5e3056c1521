"""Pictures of episodes: GIFs, plots and the three-rod demo."""
