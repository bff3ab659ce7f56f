//! Just enough Markdown for the documentation tests (`readme.rs`, `guide.rs`): the fenced
//! blocks of a document, its prose and inline code spans, its headings with the anchors GitHub
//! gives them, and its links.

/// A fenced code block: the line of its opening fence, the words after the backticks
/// (`sh runnable`), and its lines.
#[derive(Debug, PartialEq)]
pub struct Block {
    pub line: usize,
    pub info: String,
    pub body: String,
}

/// The fenced blocks of `text`, in order. `name` names the document in the panic for a block
/// left open.
pub fn fenced_blocks(name: &str, text: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut current: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        match (line.strip_prefix("```"), current.as_mut()) {
            (Some(_), Some(_)) => blocks.extend(current.take()),
            (Some(info), None) => {
                current = Some(Block {
                    line: i + 1,
                    info: info.trim().to_string(),
                    body: String::new(),
                })
            }
            (None, Some(block)) => {
                block.body.push_str(line);
                block.body.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(current.is_none(), "{name}: a code block is not closed");
    blocks
}

/// Text outside the fenced blocks, cut into prose and inline code spans.
#[derive(Debug, PartialEq)]
pub struct Inline {
    /// The line the piece starts on.
    pub line: usize,
    /// Whether the piece is the inside of a code span.
    pub code: bool,
    pub text: String,
}

/// The prose and code spans of `text`, in order. A span runs from a backtick to the next one
/// within its paragraph (a span may cross lines, not a blank line); a backtick without a
/// partner there is prose.
pub fn inline(text: &str) -> Vec<Inline> {
    let mut outside = String::new();
    let mut lines = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.starts_with("```") {
            fenced = !fenced;
            // A fence ends a paragraph.
            outside.push('\n');
            lines.push(i + 1);
        } else if !fenced {
            outside.push_str(line);
            outside.push('\n');
            lines.push(i + 1);
        }
    }
    // `lines[k]` is the document's line of the k-th line of `outside`.
    let line_of = |offset: usize| lines[outside[..offset].matches('\n').count()];
    let mut pieces = Vec::new();
    let mut start = 0;
    let mut rest = 0;
    while let Some(open) = outside[rest..].find('`').map(|i| rest + i) {
        let paragraph_end = outside[open..]
            .find("\n\n")
            .map_or(outside.len(), |i| open + i);
        match outside[open + 1..paragraph_end].find('`') {
            Some(close) => {
                let close = open + 1 + close;
                pieces.push(Inline {
                    line: line_of(start),
                    code: false,
                    text: outside[start..open].to_string(),
                });
                pieces.push(Inline {
                    line: line_of(open),
                    code: true,
                    text: outside[open + 1..close].to_string(),
                });
                start = close + 1;
                rest = start;
            }
            None => rest = open + 1,
        }
    }
    if start < outside.len() {
        pieces.push(Inline {
            line: line_of(start),
            code: false,
            text: outside[start..].to_string(),
        });
    }
    pieces
}

/// GitHub's anchor of a heading: lower case, only letters, digits, `-` and `_` kept, spaces
/// turned into `-`.
pub fn anchor(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter(|&c| c.is_alphanumeric() || c == '-' || c == '_' || c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// A heading outside the fenced blocks.
#[derive(Debug, PartialEq)]
pub struct Heading {
    pub line: usize,
    pub level: usize,
    pub title: String,
    /// The anchor links use: the id of an `<a id="..."></a>` on the line before the heading,
    /// else GitHub's.
    pub anchor: String,
}

/// The headings of `text` (`#` to `######` at the start of a line), in order.
pub fn headings(text: &str) -> Vec<Heading> {
    let mut found = Vec::new();
    let mut fenced = false;
    let mut previous = "";
    for (i, line) in text.lines().enumerate() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            let level = line.chars().take_while(|&c| c == '#').count();
            if let Some(title) = line.get(level..).and_then(|rest| rest.strip_prefix(' '))
                && (1..=6).contains(&level)
            {
                let explicit = previous
                    .strip_prefix("<a id=\"")
                    .and_then(|rest| rest.strip_suffix("\"></a>"));
                found.push(Heading {
                    line: i + 1,
                    level,
                    title: title.to_string(),
                    anchor: explicit.map_or_else(|| anchor(title), str::to_string),
                });
            }
        }
        previous = line;
    }
    found
}

/// Every anchor a link into `text` may name: its headings', GitHub's and explicit ones alike.
pub fn anchors(text: &str) -> std::collections::HashSet<String> {
    headings(text)
        .into_iter()
        .flat_map(|heading| [anchor(&heading.title), heading.anchor])
        .collect()
}

/// The targets of the links and images of `text` (`[...](TARGET)`, `![...](TARGET)`) in its
/// prose, each with its line.
pub fn links(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for piece in inline(text).into_iter().filter(|piece| !piece.code) {
        let mut line = piece.line;
        let mut rest = piece.text.as_str();
        while let Some(at) = rest.find("](") {
            line += rest[..at].matches('\n').count();
            rest = &rest[at + 2..];
            if let Some(end) = rest.find(')') {
                found.push((line, rest[..end].to_string()));
            }
        }
    }
    found
}

#[test]
fn blocks_spans_headings_and_links_are_found() {
    let text = "# T\n\nSome `co\nde` and [a link](x.md#y).\n\n```sh runnable\n`not a span`\n\
                [no](link)\n```\n<a id=\"s1\"></a>\n## 1. One `x`\n\nA lone ` backtick.\n\n\
                ![p](p.svg)\n";
    assert_eq!(
        fenced_blocks("t", text),
        [Block {
            line: 6,
            info: "sh runnable".into(),
            body: "`not a span`\n[no](link)\n".into()
        }]
    );
    let spans: Vec<_> = inline(text)
        .into_iter()
        .filter(|piece| piece.code)
        .map(|piece| (piece.line, piece.text))
        .collect();
    assert_eq!(spans, [(3, "co\nde".to_string()), (11, "x".to_string())]);
    let found: Vec<_> = headings(text)
        .into_iter()
        .map(|heading| (heading.line, heading.level, heading.anchor))
        .collect();
    assert_eq!(found, [(1, 1, "t".to_string()), (11, 2, "s1".to_string())]);
    assert!(anchors(text).contains("1-one-x"));
    assert_eq!(
        links(text),
        [(4, "x.md#y".to_string()), (15, "p.svg".to_string())]
    );
}

#[test]
fn anchors_are_made_as_github_makes_them() {
    assert_eq!(anchor("Pictures (`--svg FILE`)"), "pictures---svg-file");
    assert_eq!(
        anchor("DRN (Storm's explicit format)"),
        "drn-storms-explicit-format"
    );
    assert_eq!(
        anchor("Beyond the paper: k sub-tasks, payoffs on subsets, any believed task"),
        "beyond-the-paper-k-sub-tasks-payoffs-on-subsets-any-believed-task"
    );
}
