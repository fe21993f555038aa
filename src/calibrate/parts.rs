//! Bundled relay parts.
use thiserror::Error;

#[derive(Debug, Error)]
#[error("no bundled part `{name}`; `chatterspice parts` lists them: {known}")]
pub struct UnknownPart {
    pub name: String,
    pub known: String,
}

pub struct Part {
    pub name: &'static str,
    pub scenario: &'static str,
}

pub fn all() -> Vec<Part> {
    Vec::new()
}

pub fn find(name: &str) -> Result<Part, UnknownPart> {
    all().into_iter().find(|p| p.name == name).ok_or_else(|| UnknownPart {
        name: name.to_owned(),
        known: all().iter().map(|p| p.name).collect::<Vec<_>>().join(", "),
    })
}

pub fn table() -> String {
    String::new()
}

pub fn json() -> String {
    String::new()
}
