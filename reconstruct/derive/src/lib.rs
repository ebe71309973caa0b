//! `#[derive(Options)]`: a method's parameter struct lists its options
//! (field name and `///` doc) for the `--help` listing, the README's option
//! table and the report. The field is the one place an option's name, type
//! and doc are written; its default comes from the struct's `Default` at run
//! time, so nothing is copied that could drift.
//!
//! Fields marked `#[serde(skip)]` are not options (they cannot be set from
//! a configuration). A field without a doc comment is a compile error: an
//! option nobody can read about is not an option.

use proc_macro::TokenStream;
use proc_macro2::TokenTree;
use quote::quote;
use syn::{Data, DeriveInput, Expr, Fields, Lit, Meta, parse_macro_input};

#[proc_macro_derive(Options)]
pub fn derive_options(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    match options(&input) {
        Ok(tokens) => tokens.into(),
        Err(e) => e.to_compile_error().into(),
    }
}

fn options(input: &DeriveInput) -> syn::Result<proc_macro2::TokenStream> {
    let Data::Struct(data) = &input.data else {
        return Err(syn::Error::new_spanned(
            &input.ident,
            "Options lists the fields of a struct",
        ));
    };
    let Fields::Named(fields) = &data.fields else {
        return Err(syn::Error::new_spanned(
            &input.ident,
            "Options needs named fields",
        ));
    };
    let mut entries = Vec::new();
    for field in &fields.named {
        if field.attrs.iter().any(serde_skip) {
            continue;
        }
        let ident = field.ident.as_ref().expect("named field");
        let name = ident.to_string();
        let doc = doc_text(&field.attrs);
        if doc.is_empty() {
            return Err(syn::Error::new_spanned(
                ident,
                format!("option `{name}` has no doc comment"),
            ));
        }
        entries.push(quote! { crate::options::Field { name: #name, doc: #doc } });
    }
    let ty = &input.ident;
    let (impl_generics, ty_generics, where_clause) = input.generics.split_for_impl();
    Ok(quote! {
        impl #impl_generics crate::options::Options for #ty #ty_generics #where_clause {
            const FIELDS: &'static [crate::options::Field] = &[#(#entries),*];
        }
    })
}

/// `#[serde(skip)]` (or `skip_deserializing`): not settable, not an option.
fn serde_skip(attr: &syn::Attribute) -> bool {
    let Meta::List(list) = &attr.meta else {
        return false;
    };
    list.path.is_ident("serde")
        && list
            .tokens
            .clone()
            .into_iter()
            .any(|t| matches!(&t, TokenTree::Ident(i) if i == "skip" || i == "skip_deserializing"))
}

/// The `///` lines of a field, trimmed and joined by spaces (a paragraph).
fn doc_text(attrs: &[syn::Attribute]) -> String {
    let lines: Vec<String> = attrs
        .iter()
        .filter_map(|attr| match &attr.meta {
            Meta::NameValue(nv) if nv.path.is_ident("doc") => match &nv.value {
                Expr::Lit(lit) => match &lit.lit {
                    Lit::Str(s) => Some(s.value().trim().to_string()),
                    _ => None,
                },
                _ => None,
            },
            _ => None,
        })
        .collect();
    lines.join(" ").trim().to_string()
}
