//! Run outputs: history CSVs, VTK particle files, PNG plots and summary.json.

pub mod figures;
pub mod plot;
pub mod summary;
pub mod vtk;
