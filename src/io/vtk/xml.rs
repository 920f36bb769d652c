//! A small XML scanner, enough for VTK files: elements with attributes,
//! text borrowed from the file, children and 1-based lines.

use crate::io::IoError;
use std::borrow::Cow;
use std::path::Path;

/// An XML element: name, attributes, direct text, children, line.
///
/// The text borrows the file's bytes: a 14M-tet `.vtu` is an 880 MB file
/// whose data arrays are element text, and copying it (once into the parsed
/// string, once into the elements) tripled the reader's memory. Text split
/// by child elements (never the case for a data array) is joined in a copy.
pub(super) struct Element<'a> {
    pub(super) name: String,
    pub(super) attrs: Vec<(String, String)>,
    pub(super) text: Cow<'a, str>,
    pub(super) children: Vec<usize>,
    pub(super) line: usize,
}

/// Appends `t` to an element's text, borrowing while it is one piece.
fn push_text<'a>(text: &mut Cow<'a, str>, t: &'a str) {
    if text.is_empty() {
        *text = Cow::Borrowed(t);
    } else {
        text.to_mut().push_str(t);
    }
}

impl Element<'_> {
    pub(super) fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

fn unescape(s: &str) -> String {
    if !s.contains('&') {
        return s.to_string();
    }
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Parses the XML part of a file into a flat element list (index 0 is the root).
pub(super) fn parse_xml<'a>(path: &Path, text: &'a str) -> Result<Vec<Element<'a>>, IoError> {
    let b = text.as_bytes();
    let mut pos = 0;
    let mut line = 1;
    let mut counted = 0; // newlines counted up to here
    let line_at = |p: usize, line: &mut usize, counted: &mut usize| {
        *line += b[*counted..p].iter().filter(|&&c| c == b'\n').count();
        *counted = p;
        *line
    };
    let mut elems: Vec<Element> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let mut root_closed = false;
    while pos < b.len() {
        let lt = match b[pos..].iter().position(|&c| c == b'<') {
            Some(i) => pos + i,
            None => {
                if let Some(&top) = stack.last() {
                    push_text(&mut elems[top].text, &text[pos..]);
                }
                break;
            }
        };
        if lt > pos {
            let t = &text[pos..lt];
            match stack.last() {
                Some(&top) => push_text(&mut elems[top].text, t),
                None if !t.trim().is_empty() => {
                    let l = line_at(pos, &mut line, &mut counted);
                    return Err(IoError::at(
                        path,
                        l,
                        "text outside the XML root element: not a VTK XML file",
                    ));
                }
                None => {}
            }
        }
        let l = line_at(lt, &mut line, &mut counted);
        let rest = &text[lt..];
        let skip_to = |end: &str| -> Result<usize, IoError> {
            rest.find(end).map(|i| lt + i + end.len()).ok_or_else(|| {
                IoError::at(
                    path,
                    l,
                    format!("unterminated XML markup (no '{end}'; truncated?)"),
                )
            })
        };
        if rest.starts_with("<?") {
            pos = skip_to("?>")?;
            continue;
        }
        if rest.starts_with("<!--") {
            pos = skip_to("-->")?;
            continue;
        }
        if rest.starts_with("<!") {
            pos = skip_to(">")?;
            continue;
        }
        let end = skip_to(">")?;
        let inner = &text[lt + 1..end - 1];
        if let Some(name) = inner.strip_prefix('/') {
            let name = name.trim();
            match stack.pop() {
                Some(top) if elems[top].name == name => {
                    if stack.is_empty() {
                        root_closed = true;
                    }
                }
                Some(top) => {
                    return Err(IoError::at(
                        path,
                        l,
                        format!("</{name}> closes <{}> (malformed XML)", elems[top].name),
                    ))
                }
                None => {
                    return Err(IoError::at(
                        path,
                        l,
                        format!("</{name}> closes nothing (malformed XML)"),
                    ))
                }
            }
            pos = end;
            continue;
        }
        let (inner, self_closing) = match inner.strip_suffix('/') {
            Some(i) => (i, true),
            None => (inner, false),
        };
        let name_end = inner
            .find(|c: char| c.is_ascii_whitespace())
            .unwrap_or(inner.len());
        let name = &inner[..name_end];
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_alphanumeric() || "_-.:".contains(c))
        {
            return Err(IoError::at(
                path,
                l,
                "malformed XML tag: not a VTK XML file",
            ));
        }
        let mut attrs = Vec::new();
        let mut a = inner[name_end..].trim_start();
        while !a.is_empty() {
            let eq = a
                .find('=')
                .ok_or_else(|| IoError::at(path, l, format!("malformed attribute in <{name}>")))?;
            let key = a[..eq].trim();
            let v = a[eq + 1..].trim_start();
            let q = v.chars().next().filter(|c| *c == '"' || *c == '\'');
            let Some(q) = q else {
                return Err(IoError::at(
                    path,
                    l,
                    format!("unquoted attribute '{key}' in <{name}>"),
                ));
            };
            let close = v[1..].find(q).ok_or_else(|| {
                IoError::at(
                    path,
                    l,
                    format!("unterminated attribute '{key}' in <{name}>"),
                )
            })?;
            attrs.push((key.to_string(), unescape(&v[1..1 + close])));
            a = v[close + 2..].trim_start();
        }
        if root_closed {
            return Err(IoError::at(
                path,
                l,
                "a second root element (malformed XML)",
            ));
        }
        let id = elems.len();
        elems.push(Element {
            name: name.to_string(),
            attrs,
            text: Cow::Borrowed(""),
            children: Vec::new(),
            line: l,
        });
        if let Some(&top) = stack.last() {
            elems[top].children.push(id);
        } else if id != 0 {
            return Err(IoError::at(
                path,
                l,
                "a second root element (malformed XML)",
            ));
        }
        if !self_closing {
            stack.push(id);
        }
        pos = end;
    }
    if let Some(&top) = stack.last() {
        let l = line_at(b.len(), &mut line, &mut counted);
        return Err(IoError::at(
            path,
            l,
            format!("file ends inside <{}> (truncated?)", elems[top].name),
        ));
    }
    if elems.is_empty() {
        return Err(IoError::file(path, "no XML element: not a VTK XML file"));
    }
    Ok(elems)
}

/// The first child of `e` with tag `tag`.
pub(super) fn child_element<'a, 'b>(
    elems: &'a [Element<'b>],
    e: &Element,
    tag: &str,
) -> Option<&'a Element<'b>> {
    e.children
        .iter()
        .map(|&i| &elems[i])
        .find(|c| c.name == tag)
}

/// The `<DataArray>` children of `e`.
pub(super) fn data_arrays<'a, 'b>(elems: &'a [Element<'b>], e: &Element) -> Vec<&'a Element<'b>> {
    e.children
        .iter()
        .map(|&i| &elems[i])
        .filter(|c| c.name == "DataArray")
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_text_borrows_one_piece_and_joins_several() {
        let xml = "<a>\n 12 <b k=\"v\">in b</b> 34\n</a>";
        let elems = parse_xml(Path::new("t.xml"), xml).expect("well-formed");
        assert_eq!(elems[0].name, "a");
        assert_eq!(elems[0].text, "\n 12  34\n");
        assert!(matches!(elems[0].text, Cow::Owned(_)));
        assert_eq!(elems[1].text, "in b");
        assert!(matches!(elems[1].text, Cow::Borrowed(_)));
        assert_eq!(elems[1].attr("k"), Some("v"));
        assert_eq!(elems[1].line, 2);
    }
}
