//! # trust-overrides — `#[derive(Overrides)]`: a params struct's typed partial, derived
//!
//! A scenario overrides single fields of a preset's parameters (`[planner.manager] horizon_s =
//! 3`). The derive writes that partial from the params struct itself, so a new field is
//! overridable without a second edit: for `struct XxxParams` it generates `struct XxxOverrides`
//! with one `Option` per field (`serde`, `deny_unknown_fields`, absent fields skipped when
//! written) and `impl trust_core::Overridable for XxxParams` whose `apply` writes the given
//! fields and keeps the others. Beyond the paper (a configuration aid, no algorithm).
//!
//! What a field's override holds is its type's [`Overridable::Partial`]: the value itself for
//! numbers and flags, `T` for an `Option<T>` (the override sets `Some`), and the nested
//! `…Overrides` for a field that is itself a params struct with this derive (its fields merge one
//! by one). `#[overrides(skip)]` keeps a field out of the partial (an unknown-field error when a
//! file names it); `#[overrides(name = "Name")]` on the struct names the partial (default: the
//! struct's name with `Params` replaced by `Overrides`).
//!
//! [`Overridable::Partial`]: https://docs.rs/trust-core
//!
//! Use it on a params struct whose fields a scenario may override one by one; the trait and its
//! implementations for numbers, flags and `Option` live in `trust-core` (`trust_core::Overridable`,
//! which re-exports this derive).
#![warn(missing_docs)]

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Tokens;
use quote::{format_ident, quote};
use syn::{Data, DeriveInput, Fields, Ident, LitStr, parse_macro_input};

/// Derives `trust_core::Overridable` for a params struct with named fields and generates its
/// partial, `XxxOverrides` (crate docs). Attributes: `#[overrides(name = "Name")]` on the struct,
/// `#[overrides(skip)]` on a field.
#[proc_macro_derive(Overridable, attributes(overrides))]
pub fn derive_overridable(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    expand(&input)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

fn expand(input: &DeriveInput) -> syn::Result<Tokens> {
    let name = &input.ident;
    let Data::Struct(data) = &input.data else {
        return Err(syn::Error::new_spanned(
            name,
            "#[derive(Overridable)] takes a struct with named fields",
        ));
    };
    let Fields::Named(fields) = &data.fields else {
        return Err(syn::Error::new_spanned(
            name,
            "#[derive(Overridable)] takes a struct with named fields",
        ));
    };
    if !input.generics.params.is_empty() {
        return Err(syn::Error::new_spanned(
            &input.generics,
            "#[derive(Overridable)] takes a struct without generic parameters",
        ));
    }
    let partial = partial_name(input)?;
    let mut idents = Vec::new();
    let mut types = Vec::new();
    let mut docs = Vec::new();
    for field in &fields.named {
        if is_skipped(field)? {
            continue;
        }
        let ident = field.ident.clone().expect("named field");
        docs.push(format!("Replaces `{name}::{ident}`."));
        idents.push(ident);
        types.push(field.ty.clone());
    }
    let vis = &input.vis;
    let struct_doc = format!(
        "Fields that replace single fields of [`{name}`], each optional (a scenario's override); \
         generated from it by `#[derive(Overridable)]`. Unknown fields are errors naming the \
         field."
    );
    let apply_doc =
        format!("Writes the given fields onto a [`{name}`]; the others keep their value.");
    Ok(quote! {
        #[doc = #struct_doc]
        #[derive(Debug, Clone, PartialEq, Default, ::serde::Serialize, ::serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        #vis struct #partial {
            #(
                #[doc = #docs]
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub #idents: ::core::option::Option<<#types as ::trust_core::Overridable>::Partial>,
            )*
        }

        impl #partial {
            /// No field is given.
            pub fn is_empty(&self) -> bool {
                *self == Self::default()
            }
        }

        impl ::trust_core::Overridable for #name {
            type Partial = #partial;

            #[doc = #apply_doc]
            fn apply(&mut self, partial: &#partial) {
                #(
                    if let ::core::option::Option::Some(v) = &partial.#idents {
                        ::trust_core::Overridable::apply(&mut self.#idents, v);
                    }
                )*
            }
        }
    })
}

/// `#[overrides(name = "…")]`, else the struct's name with `Params` replaced by `Overrides`
/// (`Overrides` appended when it has no `Params`).
fn partial_name(input: &DeriveInput) -> syn::Result<Ident> {
    let mut name = None;
    for attr in input
        .attrs
        .iter()
        .filter(|a| a.path().is_ident("overrides"))
    {
        attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("name") {
                let lit: LitStr = meta.value()?.parse()?;
                name = Some(Ident::new(&lit.value(), lit.span()));
                Ok(())
            } else {
                Err(meta.error("expected `name = \"…\"`"))
            }
        })?;
    }
    Ok(name.unwrap_or_else(|| {
        let own = input.ident.to_string();
        match own.strip_suffix("Params") {
            Some(stem) => format_ident!("{stem}Overrides"),
            None => format_ident!("{own}Overrides"),
        }
    }))
}

/// Whether a field carries `#[overrides(skip)]`.
fn is_skipped(field: &syn::Field) -> syn::Result<bool> {
    let mut skip = false;
    for attr in field
        .attrs
        .iter()
        .filter(|a| a.path().is_ident("overrides"))
    {
        attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("skip") {
                skip = true;
                Ok(())
            } else {
                Err(meta.error("expected `skip`"))
            }
        })?;
    }
    Ok(skip)
}
