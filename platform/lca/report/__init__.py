"""Report layer: the paper's tables, figures and a static dashboard from run directories."""
