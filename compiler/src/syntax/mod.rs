//! Surface syntax: pest grammar, AST with spans, parser with per-item error recovery.

pub mod ast;
pub mod parser;
pub mod print;

pub use parser::parse;
