//! XML VTK files checked and rewritten before `vtkio` reads them.
//!
//! `vtkio` 0.6 reads appended raw data as XML text (a `<` byte in the
//! payload ends it), slices appended blocks and inline binary headers
//! without bounds checks, indexes the text of empty `DataArray`s and
//! unwraps a missing `Points` element: such files would panic. So each
//! appended array is moved inline as base64 (its bounds checked here), the
//! `AppendedData` element dropped, and the other cases refused as
//! malformed. Compressed payloads are refused as unsupported (this build
//! of `vtkio` has no decompressors), and a missing `header_type` is
//! written in as `UInt32`, the VTK default (`vtkio` would take `UInt64`).

use alloc::{borrow::ToOwned, format, string::String, vec::Vec};
use core::ops::Range;

use super::{
    ReadError, base64,
    error::{malformed, unsupported},
};

/// How appended blocks are stored.
struct Appended<'a> {
    /// The bytes after the `_` marker, up to `</AppendedData>`.
    payload: &'a [u8],
    base64: bool,
    /// Block header: `UInt32` or `UInt64`, and its byte order.
    header_bytes: usize,
    little: bool,
}

/// The XML VTK file `bytes` made ready for `vtkio` (see the module docs);
/// bytes that are not VTK XML are left for `vtkio` to refuse.
pub(super) fn prepare_xml(bytes: Vec<u8>) -> Result<Vec<u8>, ReadError> {
    let Some(root) = find(&bytes, b"<VTKFile", 0) else { return Ok(bytes) };
    let Some(root_end) = tag_end(&bytes, root) else { return Ok(bytes) };
    let tag = String::from_utf8_lossy(&bytes[root..root_end]).into_owned();
    if let Some(c) = attribute(&tag, "compressor").map(|r| &tag[r]).filter(|c| !c.is_empty()) {
        return Err(unsupported(format!("compressed XML VTK payloads ({c})")));
    }
    let mut edits: Vec<(Range<usize>, Vec<u8>)> = Vec::new();
    let header_bytes = match attribute(&tag, "header_type").map(|r| &tag[r]) {
        Some("UInt64") => 8,
        Some(_) => 4,
        None => {
            let at = root + b"<VTKFile".len();
            edits.push((at..at, b" header_type=\"UInt32\"".to_vec()));
            4
        }
    };
    let little = attribute(&tag, "byte_order").is_none_or(|r| &tag[r] != "BigEndian");
    let points_needed = attribute(&tag, "type")
        .is_some_and(|r| matches!(&tag[r], "UnstructuredGrid" | "PolyData" | "StructuredGrid"));
    // The appended data, if any: the header part ends where it begins.
    let (head_end, tail, appended) = match find(&bytes, b"<AppendedData", root_end) {
        None => (bytes.len(), bytes.len(), None),
        Some(at) => {
            let end = tag_end(&bytes, at).ok_or_else(|| malformed("XML VTK: AppendedData tag"))?;
            let tag = String::from_utf8_lossy(&bytes[at..end]);
            let base64 = attribute(&tag, "encoding").is_some_and(|r| &tag[r] == "base64");
            let start = bytes[end..].iter().position(|&b| b == b'_').map(|p| end + p + 1);
            let close = rfind(&bytes, b"</AppendedData>");
            let (Some(start), Some(close)) = (start, close.filter(|&c| Some(c) >= start)) else {
                return Err(malformed("XML VTK: the appended data has no `_` start or no end"));
            };
            let payload = &bytes[start..close];
            let tail = close + b"</AppendedData>".len();
            (at, tail, Some(Appended { payload, base64, header_bytes, little }))
        }
    };
    scan_head(&bytes[..head_end], appended.as_ref(), header_bytes, points_needed, &mut edits)?;
    // The file again: edits applied, the appended data left out.
    let mut out = Vec::with_capacity(bytes.len());
    let mut at = 0;
    edits.sort_by_key(|e| e.0.start);
    for (range, text) in edits {
        out.extend_from_slice(&bytes[at..range.start]);
        out.extend_from_slice(&text);
        at = range.end;
    }
    out.extend_from_slice(&bytes[at..head_end]);
    out.extend_from_slice(&bytes[tail..]);
    Ok(out)
}

/// Checks the elements of the header part `head` (everything before the
/// appended data) and records the edits moving appended arrays inline.
fn scan_head(
    head: &[u8],
    appended: Option<&Appended<'_>>,
    header_bytes: usize,
    points_needed: bool,
    edits: &mut Vec<(Range<usize>, Vec<u8>)>,
) -> Result<(), ReadError> {
    let mut has_points = true;
    let mut at = 0;
    while let Some(lt) = find(head, b"<", at) {
        at = lt + 1;
        // The element's name (a leading `/` kept: an end tag).
        let name_end = (at..head.len())
            .find(|&i| {
                head[i].is_ascii_whitespace() || head[i] == b'>' || head[i] == b'/' && i > at
            })
            .unwrap_or(head.len());
        match &head[at..name_end] {
            b"Piece" => {
                let end = tag_end(head, lt).ok_or_else(|| malformed("XML VTK: Piece tag"))?;
                has_points = false;
                if points_needed && head[end - 1] == b'/' {
                    return Err(malformed("XML VTK: a piece without points"));
                }
            }
            b"Points" => has_points = true,
            b"/Piece" if points_needed && !has_points => {
                return Err(malformed("XML VTK: a piece without points"));
            }
            b"DataArray" => {
                let end = tag_end(head, lt).ok_or_else(|| malformed("XML VTK: DataArray tag"))?;
                data_array(head, lt..end, appended, header_bytes, edits)?;
                at = end;
            }
            _ => {}
        }
    }
    Ok(())
}

/// Checks the `DataArray` whose start tag spans `tag` (to its `>`), and
/// moves it inline if it is appended.
fn data_array(
    head: &[u8],
    tag: Range<usize>,
    appended: Option<&Appended<'_>>,
    header_bytes: usize,
    edits: &mut Vec<(Range<usize>, Vec<u8>)>,
) -> Result<(), ReadError> {
    // (Byte offsets into the tag are edited: no lossy conversion.)
    let text = core::str::from_utf8(&head[tag.clone()])
        .map_err(|_| malformed("XML VTK: a DataArray tag that is not UTF-8"))?;
    let value = |name: &str| attribute(text, name).map(|r| text[r].to_owned());
    let name = value("Name").unwrap_or_default();
    let self_closing = text.ends_with('/');
    // `vtkio` multiplies the last offset by this.
    if name == "connectivity" && value("NumberOfComponents").is_some_and(|c| c.trim() != "1") {
        return Err(malformed("XML VTK: connectivity with more than one component"));
    }
    // The text inside the element (none for `<DataArray …/>`).
    let content = if self_closing {
        tag.end + 1..tag.end + 1
    } else {
        tag.end + 1..find(head, b"<", tag.end + 1).unwrap_or(head.len())
    };
    let chars = head[content.clone()].iter().filter(|b| !b.is_ascii_whitespace()).count();
    let padding = head[content.clone()].iter().filter(|&&b| b == b'=').count();
    match value("format").as_deref() {
        Some("appended") => {
            let Some(appended) = appended else {
                return Err(malformed(format!(
                    "XML VTK: array `{name}` is appended, but no AppendedData"
                )));
            };
            let offset = value("offset").and_then(|o| o.trim().parse::<usize>().ok());
            let offset = offset.ok_or_else(|| {
                malformed(format!("XML VTK: appended array `{name}` without an offset"))
            })?;
            let block = appended.block(offset).ok_or_else(|| {
                malformed(format!(
                    "XML VTK: appended array `{name}` at offset {offset} runs past the appended data \
                     ({} bytes) or is not base64",
                    appended.payload.len()
                ))
            })?;
            // `format="appended"` becomes `format="binary"`, the offset goes
            // and the block, in base64, becomes the element's text.
            let f = attribute(text, "format").expect("read above");
            edits.push((tag.start + f.start..tag.start + f.end, b"binary".to_vec()));
            let o = attribute_span(text, "offset").expect("read above");
            edits.push((tag.start + o.start..tag.start + o.end, Vec::new()));
            let mut inline = base64::encode(&block);
            if self_closing {
                // `/>` becomes `>…</DataArray>`.
                inline.splice(0..0, *b">");
                inline.extend_from_slice(b"</DataArray>");
                edits.push((tag.end - 1..tag.end + 1, inline));
            } else {
                edits.push((content, inline));
            }
        }
        Some("binary") if (chars / 4 * 3).saturating_sub(padding) < header_bytes => {
            return Err(malformed(format!(
                "XML VTK: binary array `{name}` shorter than its header"
            )));
        }
        Some("ascii") if chars == 0 => {
            return Err(malformed(format!("XML VTK: array `{name}` without data")));
        }
        _ => {}
    }
    Ok(())
}

impl Appended<'_> {
    /// The block at `offset`, header included; `None` if it runs past the
    /// payload or is not base64.
    fn block(&self, offset: usize) -> Option<Vec<u8>> {
        let h = self.header_bytes;
        let size = |header: &[u8]| -> Option<usize> {
            let header = header.get(..h)?;
            let mut b = [0u8; 8];
            if self.little {
                b[..h].copy_from_slice(header);
                usize::try_from(u64::from_le_bytes(b)).ok()
            } else {
                b[8 - h..].copy_from_slice(header);
                usize::try_from(u64::from_be_bytes(b)).ok()
            }
        };
        let p = self.payload;
        if !self.base64 {
            let n = size(p.get(offset..)?)?;
            return p.get(offset..offset.checked_add(h)?.checked_add(n)?).map(<[u8]>::to_vec);
        }
        // The header encoded alone (then padded), or with the data as one.
        let head_chars = base64::encoded_len(h);
        let head_text = p.get(offset..offset.checked_add(head_chars)?)?;
        let header = base64::decode(head_text)?;
        let n = size(&header)?;
        let mut block = if head_text.contains(&b'=') {
            let start = offset + head_chars;
            let data = base64::decode(p.get(start..start.checked_add(base64::encoded_len(n))?)?)?;
            [&header[..h], &data].concat()
        } else {
            let total = h.checked_add(n)?;
            base64::decode(p.get(offset..offset.checked_add(base64::encoded_len(total))?)?)?
        };
        block.truncate(h + n);
        (block.len() == h + n).then_some(block)
    }
}

/// The first `needle` in `bytes` from `from` on.
fn find(bytes: &[u8], needle: &[u8], from: usize) -> Option<usize> {
    bytes.get(from..)?.windows(needle.len()).position(|w| w == needle).map(|p| from + p)
}

/// The last `needle` in `bytes`.
fn rfind(bytes: &[u8], needle: &[u8]) -> Option<usize> {
    bytes.windows(needle.len()).rposition(|w| w == needle)
}

/// The index of the `>` closing the tag opened at `lt` (quoted `>` skipped).
fn tag_end(bytes: &[u8], lt: usize) -> Option<usize> {
    let mut quote = None;
    for (i, &b) in bytes.iter().enumerate().skip(lt) {
        match (quote, b) {
            (None, b'"' | b'\'') => quote = Some(b),
            (Some(q), _) if b == q => quote = None,
            (None, b'>') => return Some(i),
            _ => {}
        }
    }
    None
}

/// Where the value of attribute `name` lies in the start tag `tag`.
fn attribute(tag: &str, name: &str) -> Option<Range<usize>> {
    attribute_at(tag, name).map(|(_, value)| value)
}

/// Where attribute `name` lies in the start tag `tag`, from the space
/// before it to its closing quote.
fn attribute_span(tag: &str, name: &str) -> Option<Range<usize>> {
    attribute_at(tag, name).map(|(start, value)| start - 1..value.end + 1)
}

/// Where attribute `name` starts in the start tag `tag`, and where its
/// value lies (inside the quotes).
fn attribute_at(tag: &str, name: &str) -> Option<(usize, Range<usize>)> {
    let mut from = 0;
    while let Some(i) = tag[from..].find(name).map(|i| from + i) {
        from = i + name.len();
        if !tag[..i].ends_with(|c: char| c.is_ascii_whitespace()) {
            continue;
        }
        let Some(value) = tag[from..].trim_start().strip_prefix('=') else { continue };
        let value = value.trim_start();
        let quote = value.chars().next().filter(|&q| q == '"' || q == '\'')?;
        let start = tag.len() - value.len() + 1;
        let len = tag[start..].find(quote)?;
        return Some((i, start..start + len));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block (header + 5 data bytes) read raw, as one base64 text and
    /// with the header encoded alone, in either byte order.
    #[test]
    fn appended_blocks_in_every_encoding() {
        let data = [1u8, 2, 3, 4, 5];
        for (header_bytes, little) in [(4, true), (8, true), (4, false), (8, false)] {
            let header: Vec<u8> = match (header_bytes, little) {
                (4, true) => 5u32.to_le_bytes().to_vec(),
                (4, false) => 5u32.to_be_bytes().to_vec(),
                (_, true) => 5u64.to_le_bytes().to_vec(),
                (_, false) => 5u64.to_be_bytes().to_vec(),
            };
            let block = [&header[..], &data].concat();
            // Raw, after 3 bytes of another block.
            let payload = [&[9u8, 9, 9][..], &block, b"\n"].concat();
            let a = Appended { payload: &payload, base64: false, header_bytes, little };
            assert_eq!(a.block(3), Some(block.clone()));
            assert_eq!(a.block(4), None, "runs past the end");
            assert_eq!(a.block(usize::MAX), None);
            // Base64, joint and separate.
            let joint = [&b"AAAA"[..], &base64::encode(&block)].concat();
            let a = Appended { payload: &joint, base64: true, header_bytes, little };
            assert_eq!(a.block(4), Some(block.clone()));
            let separate =
                [&b"AAAA"[..], &base64::encode(&header), &base64::encode(&data)].concat();
            let a = Appended { payload: &separate, base64: true, header_bytes, little };
            assert_eq!(a.block(4), Some(block.clone()));
            let short = &separate[..separate.len() - 4];
            let a = Appended { payload: short, base64: true, header_bytes, little };
            assert_eq!(a.block(4), None);
        }
    }

    #[test]
    fn attributes_are_found_by_whole_name() {
        let tag = r#"<DataArray type="Int64" NameX="a" Name = 'conn' offset="12"/"#;
        assert_eq!(attribute(tag, "Name").map(|r| &tag[r]), Some("conn"));
        assert_eq!(attribute(tag, "offset").map(|r| &tag[r]), Some("12"));
        assert_eq!(attribute(tag, "format"), None);
        let span = attribute_span(tag, "offset").unwrap();
        assert_eq!(&tag[span], r#" offset="12""#);
        assert_eq!(tag_end(b"<a b='>' c=\">\">x", 0), Some(14));
    }

    /// Appended arrays move inline; `<` in the raw payload is data.
    #[test]
    fn appended_data_moves_inline() {
        let mut file = br#"<VTKFile type="ImageData" byte_order="LittleEndian">
<DataArray type="UInt8" Name="a" format="appended" offset="0"/>
<DataArray type="UInt8" Name="b" format="appended" offset="6"></DataArray>
<AppendedData encoding="raw">
_"#
        .to_vec();
        file.extend([2, 0, 0, 0, b'<', b'/', 1, 0, 0, 0, b'>']);
        file.extend(b"\n</AppendedData>\n</VTKFile>\n");
        let out = String::from_utf8(prepare_xml(file).unwrap()).unwrap();
        let want = r#"<VTKFile header_type="UInt32" type="ImageData" byte_order="LittleEndian">
<DataArray type="UInt8" Name="a" format="binary">AgAAADwv</DataArray>
<DataArray type="UInt8" Name="b" format="binary">AQAAAD4=</DataArray>

</VTKFile>
"#;
        assert_eq!(out, want);
    }
}
