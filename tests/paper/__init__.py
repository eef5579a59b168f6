"""The paper's statements and the table written from them (epc_fast.paper): a file per module."""
