//! data: URIs, which make report.html self-contained. Their base64, like the viewer's frames',
//! is the standard alphabet with padding (RFC 4648), which browsers' `atob` reads.

use base64::Engine;
use base64::engine::general_purpose::STANDARD;

/// A data: URI of `bytes` with MIME type `mime`.
pub fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!("data:{mime};base64,{}", STANDARD.encode(bytes))
}

#[cfg(test)]
mod tests {
    use base64::Engine;
    use base64::engine::general_purpose::STANDARD;

    #[test]
    fn rfc4648_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(STANDARD.encode(plain.as_bytes()), coded);
        }
        assert_eq!(STANDARD.encode([0xff, 0xfe]), "//4=");
        assert_eq!(super::data_uri("text/plain", b"foo"), "data:text/plain;base64,Zm9v");
    }
}
