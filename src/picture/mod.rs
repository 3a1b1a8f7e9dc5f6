//! What a render leaves behind for its reader: the annotated picture (the
//! render, a heat map of where the time or the traversal work went, a caption
//! with the numbers), its JSON sidecar, the PNG bytes, and the progress bar
//! while it runs. Above [`crate::render`], which traces and counts.

pub mod annotate;
pub mod colormap;
pub mod heat_map;
pub mod output;
pub mod progress;
pub mod render_report;
pub mod text;
