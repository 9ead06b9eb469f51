//! Generated blocks in a markdown file: `<!-- ob:KIND key=value key="two words" -->`, the
//! generated text, then `<!-- /ob -->`. A block whose opening comment ends its line is a
//! multi-line block (a table, a list); one that opens and closes on one line is a span inside
//! a sentence.

use std::fmt;

const OPEN: &str = "<!-- ob:";
const CLOSE: &str = "<!-- /ob -->";
const END: &str = "-->";

/// One generated block, as found in a file.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// 1-based line of its opening comment.
    pub line: usize,
    /// What it generates: `table`, `value`, `findings`...
    pub kind: String,
    /// Its `key=value` attributes, in order.
    pub attrs: Vec<(String, String)>,
    /// Byte range of the generated text (between the two comments).
    pub body: std::ops::Range<usize>,
    /// Whether it spans lines (its opening comment ends a line).
    pub multiline: bool,
}

impl Block {
    /// The attribute `key`, if given.
    pub fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// A block that cannot be parsed, with the line it starts on.
#[derive(Clone, Debug, PartialEq)]
pub struct ParseError {
    /// 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

fn line_of(text: &str, at: usize) -> usize {
    text[..at].matches('\n').count() + 1
}

/// Every block of `text`, in order.
pub fn parse(text: &str) -> Result<Vec<Block>, ParseError> {
    let mut out = Vec::new();
    let mut at = 0;
    while let Some(found) = text[at..].find(OPEN) {
        let start = at + found;
        if in_code(text, start) {
            at = start + OPEN.len();
            continue;
        }
        let line = line_of(text, start);
        let head_start = start + OPEN.len();
        let head_end = text[head_start..]
            .find(END)
            .map(|i| head_start + i)
            .ok_or_else(|| ParseError {
                line,
                message: "a block's opening comment is not closed with `-->`".into(),
            })?;
        let head = &text[head_start..head_end];
        let (kind, attrs) = parse_head(head).map_err(|message| ParseError { line, message })?;
        let body_start = head_end + END.len();
        let close = text[body_start..]
            .find(CLOSE)
            .map(|i| body_start + i)
            .ok_or_else(|| ParseError {
                line,
                message: format!("the block has no closing `{CLOSE}`"),
            })?;
        if let Some(nested) = text[body_start..close].find(OPEN) {
            return Err(ParseError {
                line: line_of(text, body_start + nested),
                message: format!("a block opens before the one of line {line} is closed"),
            });
        }
        out.push(Block {
            line,
            kind,
            attrs,
            body: body_start..close,
            multiline: text[body_start..].starts_with('\n'),
        });
        at = close + CLOSE.len();
    }
    let mut rest = at;
    while let Some(stray) = text[rest..].find(CLOSE) {
        let pos = rest + stray;
        if !in_code(text, pos) {
            return Err(ParseError {
                line: line_of(text, pos),
                message: format!("`{CLOSE}` closes no block"),
            });
        }
        rest = pos + CLOSE.len();
    }
    Ok(out)
}

/// Whether `at` lies inside inline code (an odd number of backticks before it on its line),
/// where docs show a block's syntax without making one.
fn in_code(text: &str, at: usize) -> bool {
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    text[line_start..at].matches('`').count() % 2 == 1
}

/// `KIND key=value key="a b"` into its kind and attributes.
fn parse_head(head: &str) -> Result<(String, Vec<(String, String)>), String> {
    let (kind, mut rest) = head
        .trim_end()
        .split_once(char::is_whitespace)
        .unwrap_or((head.trim_end(), ""));
    let named = |c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_';
    if kind.is_empty() || !kind.chars().all(named) {
        return Err("a block names no kind (`<!-- ob:KIND ... -->`)".into());
    }
    let mut attrs = Vec::new();
    loop {
        rest = rest.trim_start();
        if rest.is_empty() {
            break;
        }
        let (key, after) = rest
            .split_once('=')
            .ok_or_else(|| format!("`{rest}`: attributes are key=value"))?;
        let key = key.trim();
        if key.is_empty() || key.contains(char::is_whitespace) {
            return Err(format!("`{rest}`: attributes are key=value"));
        }
        let (value, after) = if let Some(quoted) = after.strip_prefix('"') {
            let end = quoted
                .find('"')
                .ok_or_else(|| format!("{key}: the quoted value is not closed"))?;
            (&quoted[..end], &quoted[end + 1..])
        } else {
            after.split_once(char::is_whitespace).unwrap_or((after, ""))
        };
        if attrs.iter().any(|(k, _): &(String, String)| k == key) {
            return Err(format!("{key} is given twice"));
        }
        attrs.push((key.to_string(), value.to_string()));
        rest = after;
    }
    Ok((kind.to_string(), attrs))
}

/// `text` with each block's generated text replaced by `fill(block)`; a multi-line block's
/// text sits on lines of its own between the two comments.
pub fn rewrite<E>(
    text: &str,
    blocks: &[Block],
    mut fill: impl FnMut(&Block) -> Result<String, E>,
) -> Result<String, E> {
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for b in blocks {
        out.push_str(&text[at..b.body.start]);
        let body = fill(b)?;
        if b.multiline {
            out.push('\n');
            out.push_str(body.trim_end_matches('\n'));
            out.push('\n');
        } else {
            out.push_str(body.trim());
        }
        at = b.body.end;
    }
    out.push_str(&text[at..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_and_blocks_parse_with_their_lines() {
        let text = "a\nDP is <!-- ob:value run=r cell=\"128 w2 dp\" -->831<!-- /ob --> FPS.\n<!-- ob:table run=r -->\n| x |\n<!-- /ob -->\n";
        let blocks = parse(text).unwrap();
        assert_eq!(blocks.len(), 2);
        assert_eq!(blocks[0].line, 2);
        assert_eq!(blocks[0].kind, "value");
        assert_eq!(blocks[0].attr("cell"), Some("128 w2 dp"));
        assert!(!blocks[0].multiline);
        assert_eq!(&text[blocks[0].body.clone()], "831");
        assert_eq!(blocks[1].line, 3);
        assert!(blocks[1].multiline);
        let out = rewrite(text, &blocks, |b| {
            Ok::<_, ()>(if b.multiline {
                "| y |\n".into()
            } else {
                "830".into()
            })
        })
        .unwrap();
        assert_eq!(
            out,
            "a\nDP is <!-- ob:value run=r cell=\"128 w2 dp\" -->830<!-- /ob --> FPS.\n<!-- ob:table run=r -->\n| y |\n<!-- /ob -->\n"
        );
    }

    #[test]
    fn a_block_shown_in_inline_code_is_no_block() {
        let text = "Write `<!-- ob:value run=R cell=C -->1<!-- /ob -->` to cite one.\n";
        assert_eq!(parse(text).unwrap(), Vec::new());
    }

    #[test]
    fn malformed_blocks_name_their_line() {
        let cases = [
            ("x\n<!-- ob:value run=r -->1\n", 2, "no closing"),
            (
                "<!-- ob:value run=r 1<!-- /ob -->",
                1,
                "attributes are key=value",
            ),
            ("<!-- ob: run=r -->1<!-- /ob -->", 1, "names no kind"),
            ("\n\n<!-- /ob -->", 3, "closes no block"),
            ("<!-- ob:v a=1 a=2 -->1<!-- /ob -->", 1, "given twice"),
            ("<!-- ob:v a=\"1 -->1<!-- /ob -->", 1, "not closed"),
            (
                "<!-- ob:v a=1 -->\n<!-- ob:v a=1 -->1<!-- /ob -->",
                2,
                "before the one of line 1",
            ),
        ];
        for (text, line, message) in cases {
            let e = parse(text).unwrap_err();
            assert_eq!(e.line, line, "{text}");
            assert!(e.message.contains(message), "{text}: {}", e.message);
        }
    }
}
