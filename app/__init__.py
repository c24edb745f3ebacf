from .none_refs import guard_none_references

guard_none_references()   # before any Qt call: PySide6 6.12.0 leaks references to None (volviz_app.none_refs)
