//! The top level of a run deck as elements, for the energy ledger: which
//! elements deliver energy (independent sources), which store it
//! (inductors, capacitors) and which dissipate it (resistors), with their
//! nodes and, where the card gives a plain number, their value; and which
//! elements the ledger cannot account for (a controlled or behavioural
//! source, a subcircuit with a source of its own), so that it says so
//! rather than balance a circuit it does not know.

use super::deck;
use super::lexical::physical_lines;
use super::number::parse_number;

/// One top-level element card.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// The card's first letter, upper case: `V`, `I`, `R`, `L`, `C`, ….
    pub kind: char,
    /// Its name as written, lower case (ngspice's vector names).
    pub name: String,
    /// Its nodes, lower case (`0` and `gnd` are ground).
    pub nodes: Vec<String>,
    /// Its value when the card gives a plain number after the nodes
    /// (`R1 a b 10k`), else `None` (an expression, a model, a source
    /// function).
    pub value: Option<f64>,
}

/// The deck's top level as the ledger reads it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Elements {
    /// Independent sources, resistors, inductors and capacitors.
    pub elements: Vec<Element>,
    /// Why the ledger cannot balance the deck, if it cannot: each an
    /// element the ledger does not account for.
    pub unaccounted: Vec<String>,
}

/// The cards of deck `text` (its title left out), lower case, each with
/// the `.subckt` block it lies in, if any.
fn cards(text: &str) -> Vec<(Option<String>, String)> {
    let lines = physical_lines(text);
    let mut live = vec![true; lines.len()];
    if let Some(title) = live.first_mut() {
        *title = false;
    }
    let mut out = Vec::new();
    let mut inside: Vec<String> = Vec::new();
    for card in deck::cards(&lines, &live) {
        let lower = card.text.to_ascii_lowercase();
        if let Some(rest) = lower.strip_prefix(".subckt") {
            inside.push(
                rest.split_whitespace()
                    .next()
                    .unwrap_or_default()
                    .to_owned(),
            );
        } else if lower.starts_with(".ends") {
            inside.pop();
        } else {
            out.push((inside.last().cloned(), lower));
        }
    }
    out
}

/// The top-level elements of deck `text`, the instances of `ours` (the
/// contact's and the coil's subcircuits, whose energy the run accounts
/// for itself) left out.
pub fn top_level(text: &str, ours: &[&str]) -> Elements {
    let cards = cards(text);
    // Subcircuits with a card that can deliver energy of its own.
    let mut sourcing: Vec<String> = Vec::new();
    for (block, card) in &cards {
        if let Some(block) = block
            && delivers(card)
        {
            sourcing.push(block.clone());
        }
    }
    let ours: Vec<String> = ours.iter().map(|s| s.to_ascii_lowercase()).collect();
    let mut found = Elements::default();
    for (block, card) in &cards {
        if block.is_some() || card.starts_with('.') {
            continue;
        }
        let words: Vec<&str> = card.split_whitespace().collect();
        let Some(kind) = words[0].chars().next().map(|c| c.to_ascii_uppercase()) else {
            continue;
        };
        match kind {
            'V' | 'I' | 'R' | 'L' | 'C' if words.len() >= 3 => {
                let value = words.get(3).and_then(|w| parse_number(w));
                found.elements.push(Element {
                    kind,
                    name: words[0].to_owned(),
                    nodes: vec![words[1].to_owned(), words[2].to_owned()],
                    value,
                });
            }
            'X' => {
                let sub = deck::subckt_of(card).unwrap_or_default();
                if !ours.contains(&sub) && sourcing.contains(&sub) {
                    found
                        .unaccounted
                        .push(format!("{} (subcircuit {sub} has a source)", words[0]));
                }
            }
            'E' | 'F' | 'G' | 'H' | 'B' | 'A' => {
                found
                    .unaccounted
                    .push(format!("{} (a controlled source)", words[0]));
            }
            'K' | 'T' | 'O' | 'U' => {
                found.unaccounted.push(format!(
                    "{} (stores energy the ledger does not read)",
                    words[0]
                ));
            }
            _ => {}
        }
    }
    found
}

/// Whether `card` (lower case) can deliver energy: an independent source
/// other than a plain 0 V current sensor, or a controlled source.
fn delivers(card: &str) -> bool {
    let words: Vec<&str> = card.split_whitespace().collect();
    match card.chars().next() {
        Some('v') => {
            let rest = &words[3.min(words.len())..];
            !(rest.is_empty()
                || (rest.len() == 1 && parse_number(rest[0]) == Some(0.0))
                || (rest.len() == 2 && rest[0] == "dc" && parse_number(rest[1]) == Some(0.0)))
        }
        Some('i' | 'e' | 'f' | 'g' | 'h' | 'b' | 'a') => true,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sources_stores_and_resistors_at_the_top_level_only() {
        let deck = "title\nV1 vcc 0 DC 12\nR1 vcc a 2.2k\n+ \nL1 a b 10m\nC1 b 0 {cval}\n\
                    X1 b 0 CONTACT\nXD a 0 DRV\nXP a 0 PASSIVE\n.subckt DRV p n\nV9 p n 5\n.ends\n\
                    .subckt PASSIVE p n\nVs p x 0\nR9 x n 1\n.ends\nE1 c 0 a 0 2\n.end\n";
        let found = top_level(deck, &["contact"]);
        let names: Vec<(char, &str, Option<f64>)> = found
            .elements
            .iter()
            .map(|e| (e.kind, e.name.as_str(), e.value))
            .collect();
        assert_eq!(
            names,
            [
                ('V', "v1", None),
                ('R', "r1", Some(2200.0)),
                ('L', "l1", Some(0.01)),
                ('C', "c1", None)
            ]
        );
        assert_eq!(found.elements[0].nodes, ["vcc", "0"]);
        assert_eq!(found.unaccounted.len(), 2, "{:?}", found.unaccounted);
        assert!(found.unaccounted[0].starts_with("xd"));
        assert!(found.unaccounted[1].starts_with("e1"));
    }
}
