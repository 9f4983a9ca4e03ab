pub use signorini_macros::forms;
