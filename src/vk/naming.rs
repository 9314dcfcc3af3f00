//! GLSL member names as Rust field names. Shared with build.rs (which
//! includes this file by path to name the Rust fields it generates from
//! `src/gpu_structs.toml`), so it uses nothing outside itself.

/// `camelCase` to `snake_case` (GLSL member names to Rust field names).
pub fn snake_case(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_uppercase() {
            out.push('_');
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}
