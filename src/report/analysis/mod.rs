//! What the reports conclude from results files, before any format draws it: the verdicts of
//! a comparison between runs or within one ([`compare`]) and how the balance points moved
//! ([`shift`]). Data in, data out; the formats ([`super::verdicts`], markdown, HTML) render it.

pub mod compare;
pub mod shift;
