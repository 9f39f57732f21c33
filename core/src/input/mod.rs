//! What users hand tetlab, before it means anything: their text files ([`text_file`], which the
//! browser provides in memory), the reference meshes beside a clone ([`shared_meshes`]), and the
//! range every number they may set must lie in ([`limits`]).

pub mod limits;
pub mod shared_meshes;
pub mod text_file;
