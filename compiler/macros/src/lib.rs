//! `forms!("path/to/file.wf")`: compiles a .wf file (and its imports) at build time into a
//! module of kernels named after the file stem; `forms!(pub mod name = "path")` names it, and
//! `forms!(mod name = "law.wf", material = "neo_hookean.wf")` binds a file to a role the unit
//! imports (`import material = elasticity`).
//! Paths are relative to the using crate's manifest directory. Errors become
//! `compile_error!` with the rendered diagnostics; editing any of the files triggers a
//! rebuild. The macro never panics: a compiler bug is reported as an error too.

#![forbid(unsafe_code)]

use std::path::{Path, PathBuf};

use proc_macro::TokenStream;
use proc_macro2::Span;
use quote::quote;
use syn::parse::{Parse, ParseStream};
use syn::{Ident, LitStr, Token, Visibility};

use signorini_compiler::{FsLoader, codegen};

struct Input {
    vis: Visibility,
    name: Option<Ident>,
    path: LitStr,
    /// Files bound to roles: `material = "forms/neo_hookean.wf"`.
    roles: Vec<(Ident, LitStr)>,
}

impl Parse for Input {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let (vis, name) = if input.peek(LitStr) {
            (Visibility::Inherited, None)
        } else {
            let vis: Visibility = input.parse()?;
            input.parse::<Token![mod]>()?;
            let name: Ident = input.parse()?;
            input.parse::<Token![=]>()?;
            (vis, Some(name))
        };
        let path = input.parse()?;
        let mut roles = Vec::new();
        while input.parse::<Option<Token![,]>>()?.is_some() && !input.is_empty() {
            let role: Ident = input.parse()?;
            input.parse::<Token![=]>()?;
            roles.push((role, input.parse()?));
        }
        Ok(Input { vis, name, path, roles })
    }
}

/// Reads the file system, with files bound to roles.
struct Bound {
    roles: Vec<(String, PathBuf)>,
}

impl signorini_compiler::Loader for Bound {
    fn load(&self, path: &Path) -> std::io::Result<String> {
        signorini_compiler::Loader::load(&FsLoader, path)
    }

    fn role(&self, role: &str) -> Option<PathBuf> {
        self.roles.iter().find(|(r, _)| r == role).map(|(_, p)| p.clone())
    }
}

#[proc_macro]
pub fn forms(input: TokenStream) -> TokenStream {
    forms_tokens(input.into()).into()
}

/// The macro on proc-macro2 tokens (testable outside the compiler).
fn forms_tokens(input: proc_macro2::TokenStream) -> proc_macro2::TokenStream {
    let input = match syn::parse2::<Input>(input) {
        Ok(i) => i,
        Err(e) => return e.to_compile_error(),
    };
    let span = input.path.span();
    match std::panic::catch_unwind(|| expand(&input)) {
        Ok(Ok(tokens)) => tokens,
        Ok(Err(msg)) => error(span, &msg),
        Err(_) => error(span, "internal error in the signorini compiler (please report it with the .wf file)"),
    }
}

fn error(span: Span, msg: &str) -> proc_macro2::TokenStream {
    let msg = format!("signorini: the forms did not compile\n\n{msg}");
    quote::quote_spanned!(span=> compile_error!(#msg);)
}

fn expand(input: &Input) -> Result<proc_macro2::TokenStream, String> {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").map(PathBuf::from).unwrap_or_default();
    let rel = input.path.value();
    let module = match &input.name {
        Some(n) => n.to_string(),
        None => signorini_compiler::module_name(Path::new(&rel)),
    };
    let opts = codegen::Options { runtime: codegen::DEFAULT_RUNTIME.to_string(), module, source_name: rel.clone() };
    let loader = Bound { roles: input.roles.iter().map(|(r, p)| (r.to_string(), manifest.join(p.value()))).collect() };
    let signorini_compiler::Expansion { mut file, sources } =
        signorini_compiler::expand(&manifest.join(&rel), &loader, &opts)?;
    if let Some(syn::Item::Mod(m)) = file.items.first_mut() {
        if input.name.is_some() {
            m.vis = input.vis.clone();
        }
        // Rebuild when any file of the unit changes.
        let deps: Vec<String> = sources.iter().map(|p| p.display().to_string()).collect();
        let track: syn::Item = syn::parse_quote! {
            const _: &[&[u8]] = &[#(include_bytes!(#deps)),*];
        };
        if let Some((_, items)) = &mut m.content {
            items.push(track);
        }
    }
    Ok(quote!(#file))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_file(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("signorini-macro-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn a_bad_file_becomes_compile_error_with_the_rendered_diagnostic() {
        let path = temp_file("bad.wf", "param E = 1.0\nform k(u; v) = int(Omega) inner(grd(u), grad(v)) * E\n");
        let lit = path.display().to_string();
        let out = forms_tokens(quote!(#lit)).to_string();
        assert!(out.starts_with("compile_error !"), "{out}");
        assert!(out.contains("unknown name `grd`"), "{out}");
        assert!(out.contains("bad.wf:2:"), "{out}");
        assert!(out.contains("did you mean `grad`?"), "{out}");
    }

    #[test]
    fn a_good_file_becomes_a_module_that_tracks_its_sources() {
        let path = temp_file("good.wf", "param rho = 2.0\nform mass(a; v) = int(Omega) rho * dot(a, v)\n");
        let lit = path.display().to_string();
        let out = forms_tokens(quote!(pub mod named = #lit)).to_string();
        assert!(out.contains("pub mod named {"), "{out}");
        assert!(out.contains("include_bytes !"), "{out}");
        assert!(out.contains("struct Mass"), "{out}");
    }

    #[test]
    fn malformed_macro_input_is_a_syntax_error_not_a_panic() {
        let out = forms_tokens(quote!(mod 42)).to_string();
        assert!(out.contains("compile_error"), "{out}");
    }
}
