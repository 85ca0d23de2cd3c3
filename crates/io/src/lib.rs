//! Run folders, VTU/PVD, CSV time series, checkpoints and plots.
